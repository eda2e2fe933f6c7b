#pragma once
/// @file The loader's last step: what the topology, once loaded, will do that cannot work, and
/// the periodic load of each bus. One place computes them; LoadedTopology carries them to
/// `canfleet check` (printed), `canfleet up` and `canfleet test` (logged). Each kind of warning
/// has its own file: heartbeat_warnings, pdo_warnings, bus_load. Internal to the loader.

#include <vector>

#include "orchestrator/topology/located_error.hpp"
#include "orchestrator/topology/topology_facts.hpp"
#include "orchestrator/topology/topology_warning.hpp"

namespace canfleet::topology::detail {

struct Feasibility {
  std::vector<TopologyWarning> warnings;
  std::vector<BusLoad> loads;  ///< one per bus, in file order
};

/// Reads a topology that passed every check, with its defaults applied.
Feasibility CheckFeasibility(const Scope& root, const TopologyFacts& facts);

}  // namespace canfleet::topology::detail
