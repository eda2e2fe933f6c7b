#include "orchestrator/topology/topology_warnings.hpp"

#include "orchestrator/topology/bus_load.hpp"
#include "orchestrator/topology/configured_port.hpp"
#include "orchestrator/topology/heartbeat_warnings.hpp"
#include "orchestrator/topology/pdo_warnings.hpp"
#include "orchestrator/topology/periodic_traffic.hpp"

namespace canfleet::topology::detail {

Feasibility CheckFeasibility(const Scope& root, const TopologyFacts& facts) {
  Feasibility out;
  const std::vector<ConfiguredPort> ports = ConfigurePorts(facts);
  const StartedNodes started = NodesStarted(facts.spec);
  const std::map<std::string, BusTraffic> traffic = TrafficByBus(facts.spec, ports, started);

  out.warnings = HeartbeatWarnings(root, ports);
  for (TopologyWarning& w : PdoWarnings(root, ports, traffic, started))
    out.warnings.push_back(std::move(w));
  for (int i = 0; i < facts.spec.bus_size(); ++i) {
    const Bus& bus = facts.spec.bus(i);
    BusLoad load = OfferedLoad(bus, traffic.at(bus.name()));
    if (std::string reason = OverloadReason(load); !reason.empty())
      out.warnings.push_back(root.Child("bus", bus, i).Warn("bitrate", std::move(reason)));
    out.loads.push_back(std::move(load));
  }
  return out;
}

}  // namespace canfleet::topology::detail
