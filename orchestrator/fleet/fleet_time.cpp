#include "orchestrator/fleet/fleet_time.hpp"

#include <cmath>
#include <stdexcept>

namespace canfleet::fleet {

host::HostTime FleetTime(const topology::Topology& spec, const TimeOverride& override) {
  host::HostTime time;
  if (override.mode.empty())
    time.virtual_time = spec.time().mode() == topology::Time::VIRTUAL;
  else if (override.mode == "virtual" || override.mode == "real")
    time.virtual_time = override.mode == "virtual";
  else
    throw std::invalid_argument("--time " + override.mode + ": real or virtual");
  time.conductor.speed = override.speed ? *override.speed : spec.time().speed();
  if (override.global_lookahead)
    time.conductor.lookahead = transport::TimeConductorOptions::Lookahead::kGlobal;
  if (time.conductor.speed < 0 || !std::isfinite(time.conductor.speed))
    throw std::invalid_argument("speed must be 0 (max) or a positive factor");
  return time;
}

void UseHostTime(FleetOptions& options, transport::TimeConductor* conductor) {
  options.conductor = conductor;
  if (conductor != nullptr)
    options.node_arguments.insert(options.node_arguments.end(), {"--time", "virtual"});
}

control::ControlHandler& ControlHandlerFor(control::ControlHandler& fleet,
                                           transport::TimeConductor* conductor,
                                           std::unique_ptr<BoundaryControlHandler>& holder) {
  if (conductor == nullptr) return fleet;
  holder = std::make_unique<BoundaryControlHandler>(fleet, *conductor);
  return *holder;
}

void BoundaryControlHandler::Handle(const control::Request& request,
                                    std::shared_ptr<control::Responder> responder) {
  conductor_.AtBoundary([this, request, responder = std::move(responder)]() mutable {
    inner_.Handle(request, std::move(responder));
  });
}

}  // namespace canfleet::fleet
