#pragma once
/// @file The topology loader's checks of expect steps (issue 21): each expectation names nodes,
/// ports and buses of the topology, gives what its kind needs (an EMCY code, a state the master
/// can see, an object the device's dictionary has, a signal the device has, a COB-ID) and a
/// window it can be judged in. Internal to the loader; topologies/README.md lists the rules.

#include "orchestrator/topology/located_error.hpp"
#include "orchestrator/topology/topology_facts.hpp"

namespace canfleet::topology::detail {

/// `s` is the scope of the step's `expect`.
void CheckExpect(const Scope& s, const TopologyFacts& facts, const Expect& expect);

}  // namespace canfleet::topology::detail
