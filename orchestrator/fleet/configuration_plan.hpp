#pragma once
/// @file What the orchestrator, as the fleet's CANopen master, writes into a node after its
/// boot-up (CiA 302's "configure the slave" step): heartbeat producer and consumers from the
/// topology, then the DCF's values that differ from the defaults, then the topology's SDO writes,
/// in that order. A pure function, so it is tested
/// without a bus.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "orchestrator/fleet/fleet_node.hpp"

namespace canfleet::fleet {

struct PlannedWrite {
  std::uint16_t index = 0;
  std::uint8_t subindex = 0;
  std::vector<std::uint8_t> data;  ///< little-endian value
  std::string what;                ///< for the log: "1017h heartbeat producer 500 ms"
};

/// Node-ID of another topology node on `bus`, or nullopt.
using NodeIdLookup =
    std::function<std::optional<std::uint8_t>(const std::string& node, const std::string& bus)>;

/// The writes for CAN port `port` of `node`. @throws std::invalid_argument when a value cannot be
/// encoded or a consumer names a node that is not on the same bus.
std::vector<PlannedWrite> PlanConfiguration(const FleetNode& node, std::size_t port,
                                            const NodeIdLookup& lookup);

}  // namespace canfleet::fleet
