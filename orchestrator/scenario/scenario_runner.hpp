#pragma once
/// @file Runs a topology's scenario on the orchestrator's scheduler (issue 21): action steps at
/// their times, expectations in their windows. Every timer is a canfleet::Timer on the Scheduler
/// it is given, so the same runner works in real time (`canfleet up`, `canfleet test`), in unit
/// tests on simulated time, and later in virtual time.
///
/// What the runner needs of a fleet is FleetProbe: reads it polls while a window is open (SDO, a
/// simulated signal, NMT state, controller state, bus load). Frames (every frame and error frame a
/// listen-only monitor sees on each bus) are pushed into it with Frame().

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "clock/scheduler.hpp"
#include "orchestrator/scenario/judge.hpp"
#include "orchestrator/topology/canfleet_topology.pb.h"

namespace canfleet::scenario {

/// The reads of a running fleet the runner polls. Answers may come later (on the same thread).
class FleetProbe {
 public:
  using SdoDone = std::function<void(std::optional<std::uint32_t> abort, std::vector<std::uint8_t> data,
                                     std::string error)>;
  using IoDone = std::function<void(std::string error, std::string value, std::string unit)>;

  virtual ~FleetProbe() = default;
  virtual void ReadSdo(const PortAddress& port, std::size_t port_index, std::uint16_t index,
                       std::uint8_t subindex, SdoDone done) = 0;
  virtual void ReadIo(const std::string& node, const std::string& name, IoDone done) = 0;
  /// From its heartbeats: "operational", "pre-operational", "stopped", "initialising", "unknown".
  virtual std::string NmtState(const PortAddress& port) const = 0;
  /// "error-active", "error-passive", "bus-off"; "" when the port is not attached.
  virtual std::string ControllerState(const PortAddress& port) const = 0;
  virtual double LoadPercent(const std::string& bus) const = 0;
};

/// One expectation's result.
struct Result {
  int step = 0;             ///< index in Topology.scenario
  std::string name;         ///< the step's name, or "scenario[i]"
  std::string description;  ///< "EMCY 8130h from quad-6 within 1500 ms after cut-hb"
  Verdict verdict;
  std::optional<TimePoint> opened;  ///< when its window opened (unset: never)
  int index = 0;                    ///< among the scenario's expectations (file order, 0-based)
};

/// Where a run stands (for monitors: telemetry's ScenarioStatus).
struct Progress {
  std::size_t expectations = 0;
  std::size_t passed = 0, failed = 0, skipped = 0, pending = 0;
  bool started = false;
  bool done = false;  ///< every step ran and every expectation is decided
  /// The latest step that began: an action that ran or an expectation whose window opened. Its
  /// name, or for an unnamed action what it does ("io quad-5 IN1.voltage_mV=1800"); "" before.
  std::string step;
  std::optional<TimePoint> step_time;
};

/// What an action step does, in a few words: "inject heartbeat-loss quad-5", "clear hb-loss",
/// "io quad-5 IN1.voltage_mV=1800", "nmt start quad-6", "sdo write quad-5 1017h sub 0".
std::string ActionText(const topology::Step& step);

struct RunnerOptions {
  /// How often reads are repeated while a window is open: reads over the bus or a node
  /// connection (SDO, simulated I/O) and reads of the orchestrator's own state (NMT state,
  /// controllers, bus load; a held bus-off is seen, a 5 ms automatic recovery may not be).
  Duration remote_poll = std::chrono::milliseconds(100);
  Duration local_poll = std::chrono::milliseconds(10);
  /// A read still unanswered this long after its window closed is given up (the judge decides
  /// on what it has).
  Duration read_grace = std::chrono::seconds(5);
  /// How long (scheduler time before now) the runner keeps the frames it was given while a window
  /// is still to open, so that a window opening later than its time judges the frames the monitor
  /// saw since then: a timer that fired late, an anchor decided by a read answered after it was
  /// asked (up to read_grace), a frame of another bus delivered before the anchor's.
  Duration frame_history = std::chrono::seconds(5);
};

class ScenarioRunner {
 public:
  struct Hooks {
    std::function<void(const topology::Step&)> act;  ///< runs an action step (inject, io, ...)
    std::function<void(const Result&)> decided;      ///< an expectation was decided
    std::function<void(int step)> began;             ///< an action ran or an expectation's window opened
    std::function<void()> done;                      ///< every step ran and every expectation is decided
  };

  /// `topology` must have loaded (topology_loader: every name resolves, defaults applied).
  /// Throws std::invalid_argument when an expectation cannot be judged (the loader refuses those).
  ScenarioRunner(Scheduler& scheduler, const topology::Topology& topology, FleetProbe& probe, Hooks hooks,
                 RunnerOptions options = {});
  ~ScenarioRunner();
  ScenarioRunner(const ScenarioRunner&) = delete;
  ScenarioRunner& operator=(const ScenarioRunner&) = delete;

  /// The scenario starts now (the fleet is ready).
  void Start();
  /// A frame seen on `bus` at `time` (bus time = scheduler time). Frames of one bus come in bus
  /// order, with their bus times, however late (a round delivered in one batch by a timer that
  /// fired late) or early (end-of-frame times ahead of now).
  void Frame(const std::string& bus, const CanFrame& frame, TimePoint time);

  /// Every expectation in file order; decided ones have their verdict.
  std::vector<Result> Results() const;
  /// Counts of this run's verdicts and the step it is at.
  Progress GetProgress() const;
  std::size_t Expectations() const { return expects_.size(); }
  bool Done() const;
  /// Some undecided expectation reads the nodes (by SDO or their simulated I/O): a frame that
  /// opens its window may start a read at once (per-node lookahead then cannot let the nodes run
  /// ahead of the bus, TimeConductor::AddReactor).
  bool MayReadOnFrames() const;
  /// When the scenario started (unset before Start).
  std::optional<TimePoint> origin() const {
    return started_ ? std::optional<TimePoint>(origin_) : std::nullopt;
  }

 private:
  struct Expectation;
  struct Action;
  /// Which frame: its bus (index in buses_) and its place in the order the runner was given them.
  struct FrameRef {
    std::size_t bus = 0;
    std::uint64_t seq = 0;
  };
  /// A frame the runner was given, kept for windows that open after it came.
  struct Heard {
    FrameRef ref;
    CanFrame frame;
    TimePoint time{};
  };
  /// `by`: the frame the anchor saw (a window opened by it judges only the frames behind it).
  void Anchored(int step, TimePoint anchor, std::optional<FrameRef> by = std::nullopt);
  void AnchorLost(int step, const std::string& why);
  void Began(int step);
  void OpenWindow(Expectation& e);
  void Replay(Expectation& e);
  std::size_t BusIndex(const std::string& bus);
  void Remember(const Heard& heard);
  const Heard& HistoryAt(std::size_t i) const { return history_[(history_head_ + i) % history_.size()]; }
  void PollOnce(Expectation& e);
  void ReadDone(Expectation& e, const Sample& sample);
  void CloseWindow(Expectation& e);
  void Finish(Expectation& e);
  void CheckDone();

  Scheduler& scheduler_;
  const topology::Topology& topology_;
  FleetProbe& probe_;
  Hooks hooks_;
  RunnerOptions options_;
  TimePoint origin_{};
  int last_step_ = -1;  ///< the latest step that began (GetProgress)
  TimePoint last_step_time_{};
  bool started_ = false;
  bool done_reported_ = false;
  std::vector<std::unique_ptr<Expectation>> expects_;
  std::vector<std::unique_ptr<Action>> actions_;
  std::vector<Expectation*> frame_targets_;  ///< Frame()'s list, kept to reuse its storage
  std::vector<std::string> buses_;           ///< FrameRef::bus indexes it
  std::uint64_t next_seq_ = 0;
  /// The frames given while a window is still to open, oldest first from history_head_ (a ring,
  /// so that keeping them allocates only while it grows).
  std::vector<Heard> history_;
  std::size_t history_head_ = 0, history_size_ = 0;
  /// Read callbacks that outlive the runner find it expired.
  std::shared_ptr<int> alive_ = std::make_shared<int>(0);
};

}  // namespace canfleet::scenario
