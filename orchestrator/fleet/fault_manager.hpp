#pragma once
/// @file Faults on demand (issue 6): each FaultSpec of the control API becomes broker rules,
/// controller faults or process actions, lives for its duration or until cleared, and is logged
/// as a fault event. The broker does the physics (design decision 3); this only translates names
/// (nodes, receivers, groups) into ports and keeps the fault event log.

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "clock/scheduler.hpp"
#include "orchestrator/broker/broker.hpp"
#include "orchestrator/control/canfleet_control.pb.h"
#include "orchestrator/fleet/fleet_node.hpp"
#include "orchestrator/fleet/supervisor.hpp"

namespace canfleet::fleet {

/// A fault that cannot be injected or cleared as asked; what() is one line for the user.
class FaultError : public std::runtime_error {
 public:
  /// @param bad_request the request is wrong in itself (an unknown node or bus, a field its kind
  ///        does not take), rather than refused by the fleet's state (Response.bad_request)
  explicit FaultError(const std::string& what, bool bad_request = false)
      : std::runtime_error(what), bad_request_(bad_request) {}
  bool bad_request() const { return bad_request_; }

 private:
  bool bad_request_;
};

class FaultManager {
 public:
  struct Context {
    broker::Broker& broker;
    Scheduler& scheduler;
    Supervisor& supervisor;
    std::function<const FleetNode*(const std::string&)> find_node;
    /// The message for a node find_node does not know (the nearest names); empty: a plain one.
    std::function<std::string(const std::string&)> unknown_node;
    TimePoint origin{};  ///< uptime 0
    /// A fault began (`started`) or ended; for the log and telemetry.
    std::function<void(const control::FaultStatus&, bool started)> on_event;
    /// Seed of the random draws of a fault that gives none: the fleet's seed (topology
    /// `time.seed`) plus the fault's id, so a run repeats itself.
    std::uint64_t seed = 0;
  };

  explicit FaultManager(Context context);
  ~FaultManager();
  FaultManager(const FaultManager&) = delete;
  FaultManager& operator=(const FaultManager&) = delete;

  /// Applies the fault now. @throws FaultError naming what is wrong (unknown node, missing
  /// cob_id, a node that is not attached...). Returns its id and summary.
  control::FaultInjected Inject(const control::FaultSpec& spec);

  /// Clears by id, by label, or everything when neither is given. Returns how many were cleared.
  /// @throws FaultError for an unknown id or label.
  std::size_t Clear(const control::FaultClear& which);

  /// Active faults, then (with `include_ended`) the ended ones, oldest first.
  std::vector<control::FaultStatus> List(bool include_ended);

 private:
  struct Fault;

  void Apply(Fault& fault);
  void ApplyBusOff(Fault& fault);
  void ApplyHeartbeatLoss(Fault& fault);
  void ApplyRpdoTimeout(Fault& fault);
  void ApplyFrameFault(Fault& fault);
  void ApplyPartition(Fault& fault);
  void ApplyBabblingIdiot(Fault& fault);
  void ApplyErrorPassive(Fault& fault);
  void ApplyProcessFault(Fault& fault);

  void End(Fault& fault, const char* state);
  /// Ends faults whose count-limited rules are all used up.
  void Sweep();
  control::FaultStatus StatusOf(const Fault& fault) const;
  std::uint64_t Hits(const Fault& fault) const;

  /// The topology's node called `name`, else a participant of that name: a client attached to the
  /// broker by name that is no node of the topology (a test's python-can bus, python/README.md).
  /// Bus and frame faults act on a participant's port as on a node's; it has no node-ID (no
  /// heartbeat to lose) and no process of this fleet. Throws FaultError when neither exists.
  const FleetNode& Node(const std::string& name) const;
  /// True when `node` is a participant (no node of the topology).
  bool IsParticipant(const FleetNode& node) const;
  /// The node's broker port on `bus` (it must be attached now).
  broker::PortId PortOf(const std::string& bus, const std::string& node) const;
  std::string BusFor(const control::FaultSpec& spec) const;
  std::vector<broker::PortId> ReceiverPorts(const std::string& bus, const control::FaultSpec& spec) const;
  double Seconds(TimePoint t) const;

  Context ctx_;
  std::vector<std::unique_ptr<Fault>> faults_;  ///< in injection order; ended ones stay for List
  std::uint32_t next_id_ = 1;
  /// Participants as Node() last found them (a std::map: references stay valid as it grows).
  mutable std::map<std::string, FleetNode> participants_;
};

}  // namespace canfleet::fleet
