#pragma once
/// @file What the orchestrator, as the fleet's CANopen master, writes into a node after its
/// boot-up (CiA 302's "configure the slave" step): heartbeat producer and consumers from the
/// topology, then the DCF's values that differ from the defaults, then the topology's SDO writes,
/// in that order. A pure function of the node's topology entry, so it is tested without a bus, and
/// both the fleet (which writes it) and the loader's warnings (which read what a node will hold,
/// `configured_port.hpp`) use this one plan.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "orchestrator/topology/canfleet_topology.pb.h"

namespace canfleet::topology {

/// Which field of the node's topology entry a write comes from.
struct PlanSource {
  enum class Field { kProducer, kConsumer, kDcf, kSdo };
  Field field = Field::kSdo;
  int index = -1;  ///< the heartbeat consumer or sdo entry (0-based); -1 for the producer and the DCF
};

struct PlannedWrite {
  std::uint16_t index = 0;
  std::uint8_t subindex = 0;
  std::vector<std::uint8_t> data;  ///< little-endian value
  std::string what;                ///< for the log: "1017h heartbeat producer 500 ms"
  PlanSource source;
};

/// Node-ID of another topology node on `bus`, or nullopt.
using NodeIdLookup =
    std::function<std::optional<std::uint8_t>(const std::string& node, const std::string& bus)>;

/// The writes for CAN port `port` of `node`, whose ports are on `buses` with `node_ids` (one each).
/// @throws std::invalid_argument when a value cannot be encoded or a consumer names a node that is
/// not on the same bus.
std::vector<PlannedWrite> PlanConfiguration(const Node& node, const std::vector<std::string>& buses,
                                            const std::vector<std::uint8_t>& node_ids, std::size_t port,
                                            const NodeIdLookup& lookup);

}  // namespace canfleet::topology
