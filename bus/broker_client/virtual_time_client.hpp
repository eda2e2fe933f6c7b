#pragma once
/// @file A node process's side of lock-step virtual time (orchestrator/broker/README.md "Virtual
/// time"): its scheduler runs only when the broker grants time. Each BrokerClientPort of the process
/// holds what the broker sends (frames, TX confirmations, controller events, node requests) until
/// the TimeGrant that follows it; once every port the grant names has its grant, the client applies
/// what they hold at the grant's time (port by port, in port order: a stated tie rule for the
/// instant), runs the node's timers up to the grant's end, and each granted port answers TimeReached
/// with the node's next deadline. A node that is not granted does not run: nothing happens to it in
/// the meantime.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "clock/granted_scheduler.hpp"

namespace canfleet {

/// Implemented by a port in virtual time (BrokerClientPort's connection).
class GrantedPort {
 public:
  virtual ~GrantedPort() = default;
  /// Applies, in order, what the broker sent before its grant.
  virtual void ApplyHeld() = 0;
  /// After ApplyHeld: whether what it applied changed the acceptance filter from the one the
  /// broker knows (the node then stops at the grant's now, see VirtualTimeClient::Granted).
  virtual bool AcceptanceChanged() { return false; }
  /// Tells the broker the node reached `time`, with its next deadline and what its timers may send
  /// (TimerOutlook), and sends what the node sent meanwhile before it.
  virtual void Reached(TimePoint time, std::optional<TimePoint> next_deadline,
                       const TimerOutlook& outlook) = 0;
};

class VirtualTimeClient {
 public:
  /// `clock_id` names the process on every port's Hello (its name and process id);
  /// `port_count`: how many ports it attaches.
  VirtualTimeClient(GrantedScheduler& scheduler, std::string clock_id, std::size_t port_count);

  GrantedScheduler& scheduler() { return scheduler_; }
  const std::string& clock_id() const { return clock_id_; }
  std::size_t port_count() const { return ports_.size(); }

  /// Port `index` sends a Hello: returns the number that names this connection to the broker
  /// (Hello.clock_attachment; never 0, never given twice), by which grants list their round's ports.
  std::uint64_t Attaching(std::size_t index);
  /// Port `index` is connected, the bus's time being `now`: the node's clock moves there (a node
  /// joins a running bus at the bus's time; time never goes back).
  void Connected(std::size_t index, GrantedPort& port, TimePoint now);
  /// Port `index` lost its connection, or its attempt (after Attaching) failed: the others no
  /// longer wait for its grants.
  void Disconnected(std::size_t index);
  /// Port `index` got TimeGrant{now, until, attachments}. Runs the node once every port of
  /// `attachments` whose connection is still open (connected, or still waiting for its HelloReply)
  /// has its grant; with no `attachments` (a broker that names none), once every connected port has.
  /// A grant that reaches further than a frame could travel (kStopLookahead) ends early, at the
  /// first instant after which an acceptance filter changed (what was applied at `now`, or a
  /// timer): the broker granted it as far as nothing the old filter lets through could reach it,
  /// and grants it again from there with the new one.
  void Granted(std::size_t index, TimePoint now, TimePoint until,
               std::span<const std::uint64_t> attachments = {});

  /// Grants run so far (tests, statistics).
  std::uint64_t Rounds() const { return rounds_; }
  /// Of those, ended early for a changed acceptance filter.
  std::uint64_t EarlyStops() const { return early_stops_; }

  /// The shortest time from a frame's submission to anything another node sees of it
  /// (TimeConductor::kLookahead): a grant no longer than this never stops early.
  static constexpr Duration kStopLookahead = std::chrono::microseconds(24);

 private:
  struct Slot {
    std::uint64_t attachment = 0;  ///< the open connection's number (attaching or connected), else 0
    GrantedPort* port = nullptr;   ///< while connected
    std::optional<TimePoint> now;
    std::optional<TimePoint> until;
    std::vector<std::uint64_t> listed;  ///< the grant's attachments
  };
  void RunIfAllGranted();
  /// A long grant, after what was applied at `now`: runs instant by instant up to `until`, and
  /// returns the first instant after which an acceptance filter changed (else `until`).
  TimePoint RunUntilFilterChange(TimePoint now, TimePoint until);
  bool AnyAcceptanceChanged();
  /// Whether the round of the grants held so far waits for `slot` (open, not granted yet).
  bool Awaited(const Slot& slot) const;

  GrantedScheduler& scheduler_;
  std::string clock_id_;
  std::vector<Slot> ports_;
  std::vector<std::size_t> round_;  ///< the ports a run serves (reused)
  std::uint64_t next_attachment_ = 1;
  std::uint64_t rounds_ = 0;
  std::uint64_t early_stops_ = 0;
  TimerOutlook outlook_;  ///< reused
  bool running_ = false;  ///< a port failing while the node runs must not start another run
  bool mismatch_logged_ = false;
  bool breach_logged_ = false;
};

}  // namespace canfleet
