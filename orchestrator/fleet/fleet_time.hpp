#pragma once
/// @file How a fleet keeps time, in one place for `canfleet up` and `canfleet test`: the topology's
/// `time`, overridden by the command line; in virtual time the nodes run on the broker's clock, the
/// fleet's time starts once its nodes have joined, and control requests are served between rounds
/// (at the current simulated time).

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

#include "orchestrator/control/control_handler.hpp"
#include "orchestrator/fleet/fleet.hpp"
#include "orchestrator/host/broker_host.hpp"
#include "orchestrator/topology/canfleet_topology.pb.h"
#include "orchestrator/transport/time_conductor.hpp"

namespace canfleet::fleet {

struct TimeOverride {
  std::string mode;               ///< "real", "virtual", or empty: the topology's
  std::optional<double> speed;    ///< simulated seconds per real second; 0 = max; unset: the topology's
  bool global_lookahead = false;  ///< TimeConductorOptions::Lookahead::kGlobal (benchmarks, comparisons)
};

/// The host's time for `spec` with `override`. Throws std::invalid_argument on a bad speed.
host::HostTime FleetTime(const topology::Topology& spec, const TimeOverride& override);

using host::kJoinTimeout;
using host::ParseSpeed;

/// Serves control requests between the conductor's rounds (a request acts at the current
/// simulated time: an SDO transfer starts then, a fault begins then).
class BoundaryControlHandler final : public control::ControlHandler {
 public:
  BoundaryControlHandler(control::ControlHandler& inner, transport::TimeConductor& conductor)
      : inner_(inner), conductor_(conductor) {}
  void Handle(const control::Request& request, std::shared_ptr<control::Responder> responder) override;

 private:
  control::ControlHandler& inner_;
  transport::TimeConductor& conductor_;
};

/// In virtual time (a conductor): the fleet's nodes run on the broker's clock (--time virtual) and
/// its status shows simulated time. Nothing in real time (nullptr).
void UseHostTime(FleetOptions& options, transport::TimeConductor* conductor);

/// What the control server serves: the fleet itself, or in virtual time the fleet between rounds
/// (a BoundaryControlHandler made in `holder`, which must outlive the server).
control::ControlHandler& ControlHandlerFor(control::ControlHandler& fleet,
                                           transport::TimeConductor* conductor,
                                           std::unique_ptr<BoundaryControlHandler>& holder);

}  // namespace canfleet::fleet
