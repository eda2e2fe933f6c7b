#include "orchestrator/topology/heartbeat_warnings.hpp"

#include <map>
#include <string>
#include <tuple>

namespace canfleet::topology::detail {

namespace {

constexpr std::uint16_t kConsumerIndex = 0x1016;
constexpr std::uint16_t kProducerIndex = 0x1017;
constexpr std::uint8_t kMaxConsumers = 127;

const ConfiguredPort* ProducerOn(const std::vector<ConfiguredPort>& ports, const ConfiguredPort& consumer,
                                 std::uint32_t node_id) {
  for (const ConfiguredPort& port : ports) {
    if (&port.node() != &consumer.node() && port.bus() == consumer.bus() && port.node_id() == node_id)
      return &port;
  }
  return nullptr;
}

// One 1016h entry of one port that names no node of its bus.
struct Missing {
  const ConfiguredPort* port;
  std::uint8_t sub;
  std::uint32_t node_id;
  std::string buses;
};

}  // namespace

std::vector<TopologyWarning> HeartbeatWarnings(const Scope& root, const std::vector<ConfiguredPort>& ports) {
  std::vector<TopologyWarning> warnings;
  // A node-ID consumer is written to every port of a multi-port device; it is wrong only when no
  // port's bus has the producer. Keyed by (node, field, entry).
  using Key = std::tuple<int, int, int>;
  std::map<Key, Missing> missing;
  std::map<Key, bool> found;
  for (const ConfiguredPort& port : ports) {
    for (std::uint8_t sub = 1; sub <= kMaxConsumers && port.Has(kConsumerIndex, sub); ++sub) {
      const ValueOrigin origin = port.Origin(kConsumerIndex, sub);
      if (origin.is_default) continue;  // the device's own entries are its business
      const std::uint32_t entry = port.Unsigned(kConsumerIndex, sub);
      // CiA 301 §7.5.2.28: bits 23..16 node-ID, bits 15..0 the consumer time in ms; 0 = unused.
      const std::uint32_t node_id = (entry >> 16) & 0xFF;
      const std::uint32_t time_ms = entry & 0xFFFF;
      if (node_id == 0 || node_id > 127 || time_ms == 0) continue;
      const Key key{port.node().index, static_cast<int>(origin.source.field), origin.source.index};
      const ConfiguredPort* producer = ProducerOn(ports, port, node_id);
      if (producer == nullptr) {
        auto [it, fresh] = missing.try_emplace(key, Missing{&port, sub, node_id, port.bus()});
        if (!fresh) it->second.buses += " or " + port.bus();
        continue;
      }
      found[key] = true;
      const std::uint32_t period_ms = producer->Unsigned(kProducerIndex, 0);
      const std::string who = port.Name() + " consumes the heartbeat of " + producer->Name() + " (node-ID " +
                              std::to_string(node_id) + " on " + port.bus() + ")";
      if (period_ms == 0) {
        warnings.push_back(port.WarnAt(
            root, kConsumerIndex, sub,
            who + ", which sends none: its 1017h is 0 (" + producer->OriginText(kProducerIndex, 0) +
                "; set its heartbeat.producer_ms). Monitoring starts with the first heartbeat (CiA 301 "
                "§7.2.8.3.2.2), so no loss is ever reported"));
      } else if (time_ms <= period_ms) {
        warnings.push_back(port.WarnAt(root, kConsumerIndex, sub,
                                       who + " within " + std::to_string(time_ms) +
                                           " ms, but it comes every " + std::to_string(period_ms) +
                                           " ms (1017h, " + producer->OriginText(kProducerIndex, 0) +
                                           "): the loss is reported while the producer runs"));
      }
    }
  }
  for (const auto& [key, m] : missing) {
    if (found[key]) continue;
    warnings.push_back(m.port->WarnAt(
        root, kConsumerIndex, m.sub,
        m.port->node().name + " consumes the heartbeat of node-ID " + std::to_string(m.node_id) +
            ", but no node of the topology has that node-ID on bus " + m.buses +
            ". Monitoring starts with the first heartbeat (CiA 301 §7.2.8.3.2.2): unless a device "
            "outside the topology sends it, no loss is ever reported"));
  }
  return warnings;
}

}  // namespace canfleet::topology::detail
