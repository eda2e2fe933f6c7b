#pragma once
/// @file A node of the running fleet as the orchestrator knows it: its topology entry resolved
/// into what the fleet's parts need (buses, node-IDs per port).

#include <cstdint>
#include <string>
#include <vector>

#include "orchestrator/topology/canfleet_topology.pb.h"

namespace canfleet::fleet {

struct FleetNode {
  topology::Node spec;
  std::vector<std::string> buses;      ///< one per CAN port
  std::vector<std::uint8_t> node_ids;  ///< one per CAN port (the single node_id repeated)
  std::string device_label;            ///< the variant, or "eds:<file name>"

  const std::string& name() const { return spec.name(); }
  bool external() const { return spec.external(); }
  /// The port index on `bus`, or -1.
  int PortOn(const std::string& bus) const {
    for (std::size_t i = 0; i < buses.size(); ++i)
      if (buses[i] == bus) return static_cast<int>(i);
    return -1;
  }
};

}  // namespace canfleet::fleet
