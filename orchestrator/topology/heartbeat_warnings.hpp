#pragma once
/// @file Heartbeat consumers that cannot work as configured (topologies/README.md "What loading
/// warns about"): a 1016h entry the topology configures (heartbeat.consumer, an SDO write or a DCF)
/// whose producer is not on the bus, sends no heartbeat (1017h = 0), or sends one less often than
/// the consumer time. Monitoring starts with the first heartbeat received (CiA 301 §7.2.8.3.2.2),
/// so a silent producer is never reported lost. Internal to the loader.

#include <vector>

#include "orchestrator/topology/configured_port.hpp"
#include "orchestrator/topology/located_error.hpp"
#include "orchestrator/topology/topology_warning.hpp"

namespace canfleet::topology::detail {

std::vector<TopologyWarning> HeartbeatWarnings(const Scope& root, const std::vector<ConfiguredPort>& ports);

}  // namespace canfleet::topology::detail
