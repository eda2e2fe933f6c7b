#pragma once
/// @file What one CAN port of a node holds once the fleet has configured it: its device's
/// dictionary defaults (node-ID applied), overwritten by the orchestrator's configuration writes
/// (configuration_plan.hpp: heartbeat producer and consumers, DCF, SDO writes) in their order. Each
/// value remembers where it comes from, so a warning can point at the field that set it. Internal
/// to the loader; the warnings read it (topology_warnings.hpp).

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "node/canopen/od/object_dictionary.hpp"
#include "orchestrator/topology/configuration_plan.hpp"
#include "orchestrator/topology/located_error.hpp"
#include "orchestrator/topology/topology_facts.hpp"

namespace canfleet::topology::detail {

/// Where a configured value comes from: the device's default, or a field of the node's entry.
struct ValueOrigin {
  bool is_default = true;
  PlanSource source;  ///< when !is_default
};

class ConfiguredPort {
 public:
  /// Port `port` of `node` (which has a node-ID on it; `spec` is its topology entry), at its
  /// dictionary defaults.
  ConfiguredPort(const NodeFacts& node, const Node& spec, std::size_t port);

  const NodeFacts& node() const { return *node_; }
  const Node& spec() const { return *spec_; }
  std::size_t port() const { return port_; }
  const std::string& bus() const { return node_->buses[port_]; }
  std::uint8_t node_id() const { return node_id_; }
  /// "quad-5", or "datalogger (port 2)" for a device with several CAN ports.
  std::string Name() const;

  /// Applies one configuration write (a sub-object the dictionary lacks is ignored: the node
  /// would refuse it, and loading already refused such a topology write).
  void Apply(const PlannedWrite& write);

  bool Has(std::uint16_t index, std::uint8_t sub) const;
  /// The value as an unsigned integer (little-endian, its low 32 bits: no communication object
  /// read here is wider); 0 when absent.
  std::uint32_t Unsigned(std::uint16_t index, std::uint8_t sub) const;
  ValueOrigin Origin(std::uint16_t index, std::uint8_t sub) const;
  /// Where the value comes from, for messages: "its default", "heartbeat.producer_ms", "sdo[2]",
  /// "its DCF".
  std::string OriginText(std::uint16_t index, std::uint8_t sub) const;
  /// A warning pointing at the field the value comes from (the node's device or eds field for a
  /// default).
  TopologyWarning WarnAt(const Scope& root, std::uint16_t index, std::uint8_t sub, std::string reason) const;

 private:
  const NodeFacts* node_;
  const Node* spec_;
  std::size_t port_;
  std::uint8_t node_id_;
  const canopen::ObjectDictionary* od_;
  std::map<std::pair<std::uint16_t, std::uint8_t>, std::pair<canopen::Bytes, PlanSource>> written_;
};

/// Every port of every node that has a node-ID (255, an LSS slave waiting for one, is not
/// configured), configured as the fleet will configure it.
std::vector<ConfiguredPort> ConfigurePorts(const TopologyFacts& facts);

}  // namespace canfleet::topology::detail
