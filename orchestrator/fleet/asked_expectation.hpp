#pragma once
/// @file An expectation asked through the control API (ExpectRequest): a scenario of one step,
/// judged by the scenario's own runner and judges on what the fleet shows from the moment it was
/// asked. Internal to the fleet (fleet_clock.cpp).

#include <memory>
#include <vector>

#include "orchestrator/fleet/scenario_tap.hpp"
#include "orchestrator/scenario/scenario_runner.hpp"
#include "orchestrator/topology/topology_loader.hpp"

namespace canfleet::fleet {

struct AskedExpectation {
  topology::LoadedTopology topology;  ///< the fleet's, with this one step as its scenario
  std::unique_ptr<scenario::ScenarioRunner> runner;
  std::vector<std::unique_ptr<ScenarioTap>> taps;  ///< one per bus, before the runner goes
  ~AskedExpectation() { taps.clear(); }
};

}  // namespace canfleet::fleet
