#pragma once
/// @file The topology loader's checks of the scenario: every step has an action; fault
/// injections are what their kind takes and needs (the table of fault kinds,
/// orchestrator/control/fault_kinds.hpp, which the CLI and the fleet's FaultManager read too) on
/// nodes and buses of the topology; clears name a label injected earlier; io, nmt and sdo steps
/// are checked as the nodes' own. Internal to the loader.

#include <map>
#include <set>
#include <string>

#include "orchestrator/control/canfleet_control.pb.h"
#include "orchestrator/topology/located_error.hpp"
#include "orchestrator/topology/topology_facts.hpp"

namespace canfleet::topology::detail {

class ScenarioChecks {
 public:
  /// Every node and bus must be known in `facts` already.
  explicit ScenarioChecks(const TopologyFacts& facts) : facts_(facts) {}

  /// Every scenario[...] step, in the order they run (by at_ms, then file order): "earlier"
  /// for labels means that.
  void CheckScenario(const Scope& root);

 private:
  void CheckInject(const Scope& s, const control::FaultSpec& f, int step, std::map<std::string, int>& labels);
  static void CheckClear(const Scope& s, const control::FaultClear& c,
                         const std::map<std::string, int>& labels);
  /// A repeating scenario (scenario_repeat_ms) has steps, and clears every lasting fault it labels.
  void CheckRepeat(const Scope& root, const std::map<std::string, int>& labels,
                   const std::set<std::string>& cleared) const;

  const TopologyFacts& facts_;
};

}  // namespace canfleet::topology::detail
