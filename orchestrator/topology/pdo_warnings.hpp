#pragma once
/// @file PDO wiring that cannot work as configured (topologies/README.md "What loading warns
/// about"), read from each bus's traffic (periodic_traffic.hpp):
///  - an RPDO with a deadline (event timer, 1400h sub 5) whose COB-ID no started node on its bus
///    transmits: the deadline starts with the first frame, so no timeout is ever reported;
///  - an RPDO with a deadline fed by a TPDO that is not sent more often than the deadline (or only
///    on a change, on request, acyclically): it times out while the producer runs;
///  - an RPDO whose mapping length differs from the TPDO it receives: an RPDO length error
///    (EMCY 8210h/8220h) at every frame;
///  - a SYNC-driven TPDO (types 0..240) on a bus without a SYNC producer: never sent;
///  - two started TPDOs with one COB-ID on a bus: two transmitters of one identifier collide.
/// Only nodes the fleet starts (periodic_traffic.hpp) run PDOs. Internal to the loader.

#include <map>
#include <string>
#include <vector>

#include "orchestrator/topology/configured_port.hpp"
#include "orchestrator/topology/located_error.hpp"
#include "orchestrator/topology/periodic_traffic.hpp"
#include "orchestrator/topology/topology_warning.hpp"

namespace canfleet::topology::detail {

std::vector<TopologyWarning> PdoWarnings(const Scope& root, const std::vector<ConfiguredPort>& ports,
                                         const std::map<std::string, BusTraffic>& traffic,
                                         const StartedNodes& started);

}  // namespace canfleet::topology::detail
