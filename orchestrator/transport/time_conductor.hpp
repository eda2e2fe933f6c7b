#pragma once
/// @file Lock-step virtual time on the broker's side (design decision 10, README of
/// orchestrator/broker, "Virtual time"): the broker owns the clock of its buses and grants time to
/// the node processes, so that a fleet runs deterministically and as fast as its processes go.
///
/// The scheme is conservative (ns-3's global next-event bound, FMI-LS-BUS), in rounds. Between
/// rounds every node process and the broker stand at the same time T, with everything due by T
/// done. A round:
///   1. A = the earliest time a node can act: T if something was sent to it at T (frames that
///      ended at T, a controller event, a node request, its HelloReply), else its next deadline.
///      B = the broker's next deadline (the end of the frame on the wire, a fault's or a
///      scenario's timer...).
///   2. G = min(B, A + L), where L = kLookahead is the shortest time from a frame's submission to
///      anything another node can see of it (the shortest transfer attempt on a bus at 1 Mbit/s).
///      Nothing the nodes do in (T, G] can reach a node before G.
///   3. Every node process with something at T or a deadline by G is granted G (TimeGrant); the
///      others stand still, which is the same as running with nothing to do. Each answers
///      TimeReached with its next deadline, after the frames it sent, stamped with their times.
///   4. The broker runs its scheduler up to G, putting each node's frame on its bus at the frame's
///      time (ties: by time, then node process name, bus and order sent), so arbitration, error
///      counters and faults are those of real time; frames end at their exact times, and those
///      ending at G go to their receivers, held for the next round.
/// Outside inputs (control requests, new connections) are applied between rounds: at T, never
/// inside a round. Time stands still while no node process takes part, and while Hold()s last.
///
/// Per-node lookahead (issue 34, the default when time runs free): instead of one G for all, each
/// node process is granted as far as nothing it listens to can reach it (grant_horizon.hpp: its
/// acceptance filters, what the others' timers may send, the frames on the buses, the broker's own
/// timers), and the broker runs the buses up to the earliest deadline of any process, stopping at
/// the first instant something reaches a process. Processes then stand at different times, all at
/// or after the bus's: an outside input waits until the bus has caught up with the furthest of them
/// (the frontier), and is applied there. A bus that is not calm (a fault may corrupt, a controller
/// is error-passive...) holds each of its processes to the earliest timer on it, as above. A process
/// whose filter changes stops at the grant's now (virtual_time_client.hpp). Driven (a test steps
/// time) or paced (speed > 0), the conductor grants as above with one G for all
/// (TimeConductorOptions::lookahead).
///
/// Threading: the thread of the broker's event loop, like the broker.

#include <asio/io_context.hpp>
#include <asio/steady_timer.hpp>
#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "bus/wire/frame_record.hpp"
#include "clock/granted_scheduler.hpp"
#include "orchestrator/broker/broker.hpp"
#include "orchestrator/transport/acceptance.hpp"
#include "orchestrator/transport/grant_horizon.hpp"

namespace canfleet::transport {

/// A connection in virtual time, as the conductor sees it (NodeSession).
class GrantedSession {
 public:
  virtual ~GrantedSession() = default;
  /// Sends TimeGrant{now, until, attachments} after whatever was sent to the node since its last
  /// grant. `attachments`: the Hello.clock_attachment of each of the process's sessions this round
  /// grants (this one's included), by which the process knows which of its ports to wait for.
  virtual void SendGrant(TimePoint now, TimePoint until, std::span<const std::uint64_t> attachments) = 0;
  /// The node did not answer in time: close the connection, saying why.
  virtual void Evict(const std::string& reason) = 0;
  /// For logs: "session 3 [quad-5 on can0, port 7]".
  virtual const std::string& Label() const = 0;
  /// The bus it is attached to (orders simultaneous frames of one process's ports).
  virtual const std::string& Bus() const = 0;
  /// What the node listens to on it (wire::Acceptance); every frame until it says.
  virtual const Acceptance& Accepting() const {
    static const Acceptance every;
    return every;
  }
};

/// What a node process's timers may send (TimeReached's outlook, grant_horizon.hpp).
struct SendOutlook {
  std::optional<TimePoint> any;  ///< any identifier from then on; nullopt: no timer that may
  std::vector<ConfinedSend> confined;
};

struct TimeConductorOptions {
  /// Simulated seconds per real second; 0: as fast as the processes go ("--speed max").
  double speed = 0;
  /// How far node processes are granted: each its own way (per-node lookahead, issue 34), or all
  /// to one G (the lookahead of the earliest; what driven and paced time always use).
  enum class Lookahead : std::uint8_t { kPerNode, kGlobal } lookahead = Lookahead::kPerNode;
  /// A node process that has not answered a grant within this (real time) is treated as
  /// disconnected, so a killed or stalled process does not stop the fleet's time.
  std::chrono::milliseconds grace{10'000};
};

struct TimeConductorStats {
  std::uint64_t rounds = 0;       ///< rounds run (with or without node processes)
  std::uint64_t grants = 0;       ///< TimeGrants sent
  std::uint64_t frames = 0;       ///< node frames put on the buses at their times
  std::uint64_t evictions = 0;    ///< sessions closed for not answering in time
  std::uint64_t late_frames = 0;  ///< frames stamped before the bus's time (applied at it)
  std::uint64_t early_stops = 0;  ///< grants ended at their now (a changed acceptance filter)
  /// Something reached a process before the time it had been granted to: a broken premise of
  /// per-node lookahead (a node's timer that sent what it had not said). 0 unless a bug.
  std::uint64_t causality_errors = 0;
  std::chrono::nanoseconds wall{0};       ///< real time spent running (not held, not idle)
  std::chrono::nanoseconds simulated{0};  ///< simulated time run meanwhile
};

class TimeConductor {
 public:
  /// Shortest time from a submission to anything another port can see: a transfer attempt
  /// destroyed after kRateErrorAttemptBits (24) bit times at 1 Mbit/s, the fastest rate a port
  /// may run at. Shorter frames do not exist on classical CAN.
  static constexpr Duration kLookahead = std::chrono::microseconds(24);

  TimeConductor(asio::io_context& io, GrantedScheduler& scheduler, broker::Broker& broker,
                TimeConductorOptions options = {});
  ~TimeConductor();
  TimeConductor(const TimeConductor&) = delete;
  TimeConductor& operator=(const TimeConductor&) = delete;

  // --- sessions (NodeSession) ---
  /// A node process's port joins at the current time (call it between rounds: from AtBoundary).
  /// `clock_id` groups the ports of one process; it is granted on all of them together, each grant
  /// naming them all by their `attachment` (Hello.clock_attachment; 0: not named). `clock_ports`:
  /// how many ports the process attaches (Hello.clock_ports; 0: not stated, one).
  void Join(GrantedSession& session, const std::string& clock_id, std::uint64_t attachment = 0,
            std::uint32_t clock_ports = 1);
  /// The session ends (disconnected, closed, evicted): its process is no longer waited for on it.
  void Leave(GrantedSession& session);
  /// Something was sent to the session's node at the current time: it takes part in the next round.
  /// `reacts_after`: what was sent makes it send nothing before that long (heartbeats it only
  /// watches, Acceptance::Passive); 0: it may answer at once.
  void Pending(GrantedSession& session, Duration reacts_after = Duration::zero());
  /// Frames the node sent, stamped with their times: put on the bus at those times.
  void Submit(GrantedSession& session, broker::PortId port, std::span<const wire::StampedFrame> frames);
  /// TimeReached from the session's node, with what its timers may send (nullptr: anything, from
  /// its next deadline). False on a protocol violation (not granted; not the grant's end nor, for
  /// a grant longer than kLookahead, a time within it: an early stop for a changed filter).
  bool Reached(GrantedSession& session, TimePoint time, std::optional<TimePoint> next_deadline,
               const SendOutlook* outlook = nullptr);
  bool Participates(const GrantedSession& session) const { return sessions_.contains(&session); }

  // --- the broker's own ports that answer at once (the fleet's CANopen master) ---
  /// What a reactor may answer at once.
  enum class Reaction : std::uint8_t {
    kBootUps,            ///< a boot-up (it configures the node)
    kBootUpsAndAnswers,  ///< and an SDO server's answer (its SDO client is busy)
    kAnything,           ///< any frame, with frames or node requests (a scenario that reads nodes)
  };
  /// A port of this process on `bus` that may send as soon as it hears something: the fleet's
  /// CANopen master configures a node when it sees its boot-up, its SDO client answers a server,
  /// a scenario's expectation may read a node when a frame opens its window; `reaction()` says
  /// which now. Per-node lookahead counts it as a process with no timers of its own (its timers
  /// are the broker's); kAnything holds its bus as one that is not calm. Without it, a port that
  /// transmits and is no node process keeps its bus from being calm. Returns the id for
  /// RemoveReactor.
  std::uint64_t AddReactor(std::string bus, std::function<Reaction()> reaction);
  void RemoveReactor(std::uint64_t id);

  // --- outside inputs ---
  /// Runs `action` at the current time between rounds: now if no round is open, else when the
  /// open round ends.
  void AtBoundary(std::function<void()> action);
  /// Time stands still until as many Release() calls (the fleet holds it until its nodes joined).
  void Hold();
  void Release();
  /// Holds time until `processes` node processes have joined, each on every port it attaches (a
  /// fleet's nodes all start at the same simulated time, whatever their real start-up order), or
  /// `timeout` of real time has passed (then it says how many joined, and time goes on).
  void HoldUntilJoined(std::size_t processes, std::chrono::milliseconds timeout);
  /// Holds time until the node process of `clock_id` (Hello.clock_id: "name#pid") has joined on
  /// every port it attaches, or StopWaitingFor(clock_id), or `timeout` of real time: a process the
  /// fleet (re)starts while time runs (a restart or power-cycle fault, a crash's restart) joins at
  /// the simulated time it was started, however long it takes to start in real time.
  void HoldUntilProcessJoins(const std::string& clock_id, std::chrono::milliseconds timeout);
  /// The process will not join (it ended before it did).
  void StopWaitingFor(const std::string& clock_id);

  // --- a driver: a test process that runs the fleet's time in steps (python/canfleet) ---
  /// From the next round on, time runs only inside Advance() (until as many Undrive() calls): a
  /// test's actions then happen between its steps, at exact simulated times.
  void Drive();
  void Undrive();
  bool Driven() const { return drives_ > 0; }
  /// Runs time from now up to `until` and then calls `done(woken)` between rounds: at `until`, or
  /// earlier at the end of the round in which Wake() was called (something reached the driver: a
  /// frame for its bus participant, an answer to its control request). While time is held
  /// (Hold(), nodes still joining) it waits. Only while Driven(); one at a time.
  /// @throws std::logic_error when not driven or another Advance runs
  void Advance(TimePoint until, std::function<void(bool woken)> done);
  /// Ends the running Advance at the end of the current round (nothing when none runs).
  void Wake() {
    if (advance_done_) advance_woken_ = true;
  }
  bool Advancing() const { return static_cast<bool>(advance_done_); }

  TimePoint Now() const { return scheduler_.Now(); }
  /// Achieved factor (simulated / real time) while running; 0 before any round.
  double Factor() const;
  const TimeConductorStats& Stats() const { return stats_; }
  double Speed() const { return options_.speed; }

 private:
  struct Participant {
    std::string clock_id;
    std::vector<GrantedSession*> sessions;
    std::size_t ports = 1;                    ///< how many the process attaches (Hello.clock_ports)
    std::optional<TimePoint> next;            ///< its next deadline, as last reported
    bool pending = false;                     ///< something was sent to it at the current time
    Duration reacts_after{};                  ///< while pending: it sends nothing on it before now + this
    TimePoint reached{};                      ///< the time it has run to (at or after the bus's)
    SendOutlook outlook;                      ///< what its timers may send, as last reported
    bool has_outlook = false;                 ///< it said (else: anything from `next`)
    std::vector<HorizonPort> ports_of_round;  ///< its sessions' buses and filters (reused)
    std::size_t round_index = 0;              ///< in order_ (ComputeHorizons)
  };
  struct SessionState {
    Participant* participant = nullptr;
    std::uint64_t attachment = 0;  ///< the process's number for the connection (Hello.clock_attachment)
    bool granted = false;          ///< granted in the open round and not answered yet
    TimePoint now{}, until{};      ///< its grant in the open round
  };
  struct Submission {
    TimePoint time;
    const Participant* participant;
    const std::string* bus_key;
    std::uint64_t sequence;
    broker::PortId port;
    CanFrame frame;
  };

  /// Node processes joined on every port they attach.
  std::size_t JoinedProcesses() const;
  void Kick();
  void StartRound();
  /// Opens a round to G; false when nothing is due (idle) or pacing delays it.
  bool OpenRound();
  /// The same with per-node lookahead: each process to its own horizon.
  bool OpenPerNodeRound(TimePoint now);
  /// Marks every session of `p` granted from `now` to `until` in the round being opened.
  void MarkGranted(Participant& p, TimePoint now, TimePoint until);
  /// Grants each session marked granted (SessionState::now/until), in a stated order; closes the
  /// round at once when none is, else waits for the answers (the grace timer). True.
  bool SendGrants();
  /// Submissions in the order they go on the buses (ties: README "Ties").
  void SortSubmissions();
  /// Puts a node's frame on its bus at its stamp.
  void PutOnBus(const Submission& s);
  void CloseRound();
  void AdvanceBroker(TimePoint until);
  /// Per-node lookahead: runs the bus up to `until`, instant by instant, and stops after the first
  /// instant at which something reached a process (or a hold began).
  void AdvanceBrokerUntilInput(TimePoint until);
  /// Fills nodes_/buses_ for the participants (order_) and computes their horizons.
  void ComputeHorizons(TimePoint now, std::optional<TimePoint> cap);
  bool PerNode() const {
    return options_.lookahead == TimeConductorOptions::Lookahead::kPerNode && drives_ == 0 &&
           options_.speed == 0;
  }
  /// The furthest time a process has run to (Now() when none is ahead).
  TimePoint Frontier() const;
  /// No process stands beyond the bus's time: outside inputs may be applied now.
  bool CaughtUp() const { return Frontier() <= Now(); }
  void MarkPending(Participant& p, Duration reacts_after = Duration::zero());
  void RunBoundaryActions();
  /// Forgets processes whose every session left (and the frames they still had to go).
  void Prune();
  void OnGraceExpired();
  /// Driven: whether the running Advance stops now (it then calls its `done`); true also when no
  /// Advance runs (time stands still).
  bool AdvanceStops();
  void FinishAdvance();
  /// The grace timer, for the open round's deadline `at` (real time).
  void ArmGrace(std::chrono::steady_clock::time_point at);

  asio::io_context& io_;
  GrantedScheduler& scheduler_;
  broker::Broker& broker_;
  TimeConductorOptions options_;
  asio::steady_timer grace_timer_;
  bool grace_armed_ = false;
  std::chrono::steady_clock::time_point round_opened_{};  ///< real time the open round began
  asio::steady_timer pace_timer_;
  asio::steady_timer join_timer_;
  std::optional<std::size_t> join_target_;  ///< HoldUntilJoined's count, while it holds
  /// HoldUntilProcessJoins: the processes awaited, each with its timeout (one Hold each).
  std::map<std::string, std::unique_ptr<asio::steady_timer>> awaited_;

  std::map<std::string, Participant> participants_;  ///< by clock id: stable nodes, ordered names
  std::unordered_map<const GrantedSession*, SessionState> sessions_;
  std::vector<Submission> submissions_;
  std::uint64_t next_sequence_ = 0;
  std::deque<std::function<void()>> boundary_;
  std::vector<std::uint64_t> attachments_;  ///< the grant being sent names these (reused)

  struct Reactor {
    std::uint64_t id = 0;
    std::string bus;
    std::function<Reaction()> reaction;
    std::vector<HorizonPort> ports;  ///< one (reused)
  };
  std::vector<Reactor> reactors_;
  std::uint64_t next_reactor_ = 1;
  /// What a reactor answers: boot-ups (700h + node-ID, whose heartbeats it only watches), and SDO
  /// answers (580h + node-ID) while busy.
  Acceptance boot_ups_, boot_ups_and_answers_;

  // Per-node lookahead (reused between rounds).
  std::vector<Participant*> order_;
  std::vector<std::string> bus_names_;
  std::vector<HorizonBus> buses_;
  std::vector<std::size_t> bus_sessions_;  ///< per bus: sessions of participants on it
  std::vector<bool> anything_;             ///< per bus: a reactor may answer anything at once
  std::vector<HorizonNode> nodes_;
  std::vector<KnownFrame> known_;
  broker::BusOutlook bus_outlook_;
  TimerOutlook broker_timers_;
  GrantHorizons horizons_;
  std::size_t pending_count_ = 0;  ///< participants with pending set
  bool per_node_round_ = false;    ///< the open round grants per node
  bool causality_logged_ = false;
  /// The furthest a round may grant beyond the bus's time: a bound for a process that nothing can
  /// reach (it has its deadlines; the outside inputs wait for the bus to catch up with it).
  static constexpr Duration kMaxGrant = std::chrono::seconds(1);

  bool round_open_ = false;
  bool advancing_ = false;
  bool granting_ = false;  ///< sending a round's grants (a reply may come from inside one)
  bool start_posted_ = false;
  bool pacing_ = false;
  TimePoint round_until_{};
  std::size_t outstanding_ = 0;
  int holds_ = 0;
  int drives_ = 0;
  TimePoint advance_until_{};
  std::function<void(bool)> advance_done_;  ///< set while an Advance runs
  bool advance_woken_ = false;

  // Pacing and the achieved factor: real and simulated time since running started.
  /// Running since (real, simulated); reset when time stood still (held, idle, no node).
  std::optional<std::chrono::steady_clock::time_point> run_wall_start_;
  TimePoint run_sim_start_{};
  std::chrono::steady_clock::time_point last_wall_{};  ///< when the last round closed
  TimeConductorStats stats_;
  std::shared_ptr<int> alive_ = std::make_shared<int>(0);
};

}  // namespace canfleet::transport
