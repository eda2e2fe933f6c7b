#pragma once
/// @file The topology loader's checks of nodes: names, devices or EDS files, buses and node-IDs,
/// state folders, simulated I/O, SDO writes, restart policies, log levels, then heartbeat
/// producers and consumers. Internal to the loader (topologies/README.md lists the rules).

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <string_view>

#include "node/devices/registry.hpp"
#include "orchestrator/topology/located_error.hpp"
#include "orchestrator/topology/topology_facts.hpp"

namespace canfleet::topology::detail {

class NodeChecks {
 public:
  /// Adds what it learns to `facts` (buses must be known already).
  explicit NodeChecks(TopologyFacts& facts) : facts_(facts) {}

  /// Every node[...]: name, device or eds (and dcf), buses, node-IDs, state folder, io, sdo,
  /// heartbeat producer time, restart policy and log level.
  void CheckNodes(const Scope& root);
  /// Every node[...].heartbeat consumer, once every node is known: the producer it names, its
  /// node-ID and timeout, the device's 1016h capacity.
  void CheckHeartbeats(const Scope& root);

 private:
  void CheckDevice(const Scope& s, const Node& node, NodeFacts& facts);
  void CheckBusesOfNode(const Scope& s, const Node& node, NodeFacts& facts);
  /// Unconfigured LSS slaves on one bus are told apart by their serial number (1018h sub 4).
  void CheckUnconfiguredSerials(const Scope& s, const Node& node, const NodeFacts& facts) const;
  void CheckIo(const Scope& s, const Node& node, NodeFacts& facts);

  TopologyFacts& facts_;
  // One set of signals per variant, shared by the nodes that use it: io checks only ask whether a
  // value would be accepted.
  std::map<std::string, std::unique_ptr<devices::SimulatedIo>> signals_;
};

/// The node's signal called `name` (an old name warns, naming the new one); an unknown name fails
/// with the nearest names and the list of the node's signals (inputs only when `inputs_only`).
devices::IoName ResolveSignal(const Scope& s, std::string_view name_field, const NodeFacts& facts,
                              const std::string& name, bool inputs_only);

/// An input of the node's device set to `value` (node io and scenario io steps).
void CheckIoSet(const Scope& s, std::string_view name_field, std::string_view value_field,
                const NodeFacts& facts, const std::string& name, const std::string& value);

/// An SDO write to the node (node sdo lists and scenario sdo steps): the request is well-formed
/// and the node's dictionary has a writable object of that size there. `port` is 0-based; a port
/// the node lacks is reported at `port_field` (PortFieldName: "can" or the deprecated "port").
void CheckSdo(const Scope& s, const NodeFacts& facts, std::uint32_t index, std::uint32_t subindex,
              const std::string& type_name, const std::string& value, std::uint32_t port,
              const char* port_field);

}  // namespace canfleet::topology::detail
