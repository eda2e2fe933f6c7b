#include "orchestrator/topology/configured_port.hpp"

#include <exception>

#include "node/canopen/od/value.hpp"

namespace canfleet::topology::detail {

ConfiguredPort::ConfiguredPort(const NodeFacts& node, const Node& spec, std::size_t port)
    : node_(&node),
      spec_(&spec),
      port_(port),
      node_id_(static_cast<std::uint8_t>(node.ids.at(port))),
      od_(&node.dictionaries->at(port)) {}

std::string ConfiguredPort::Name() const {
  if (node_->ports == 1) return node_->name;
  return node_->name + " (port " + std::to_string(port_ + 1) + ")";
}

void ConfiguredPort::Apply(const PlannedWrite& write) {
  if (od_->Find(write.index, write.subindex) == nullptr) return;
  written_[{write.index, write.subindex}] = {write.data, write.source};
}

bool ConfiguredPort::Has(std::uint16_t index, std::uint8_t sub) const {
  return od_->Find(index, sub) != nullptr;
}

std::uint32_t ConfiguredPort::Unsigned(std::uint16_t index, std::uint8_t sub) const {
  if (const auto it = written_.find({index, sub}); it != written_.end())
    return static_cast<std::uint32_t>(canopen::DecodeUnsignedLe(it->second.first));
  const canopen::SubObject* object = od_->Find(index, sub);
  if (object == nullptr) return 0;
  return static_cast<std::uint32_t>(canopen::DecodeUnsignedLe(object->DefaultFor(node_id_)));
}

ValueOrigin ConfiguredPort::Origin(std::uint16_t index, std::uint8_t sub) const {
  if (const auto it = written_.find({index, sub}); it != written_.end()) return {false, it->second.second};
  return {};
}

std::string ConfiguredPort::OriginText(std::uint16_t index, std::uint8_t sub) const {
  const ValueOrigin origin = Origin(index, sub);
  if (origin.is_default) return "its default";
  switch (origin.source.field) {
    case PlanSource::Field::kProducer:
      return "heartbeat.producer_ms";
    case PlanSource::Field::kConsumer:
      return "heartbeat.consumer[" + std::to_string(origin.source.index) + "]";
    case PlanSource::Field::kDcf:
      return "its DCF";
    case PlanSource::Field::kSdo:
      break;
  }
  return "sdo[" + std::to_string(origin.source.index) + "]";
}

TopologyWarning ConfiguredPort::WarnAt(const Scope& root, std::uint16_t index, std::uint8_t sub,
                                       std::string reason) const {
  const Scope n = root.Child("node", *spec_, node_->index);
  const ValueOrigin origin = Origin(index, sub);
  if (origin.is_default) return n.Warn(spec_->eds().empty() ? "device" : "eds", std::move(reason));
  const int k = origin.source.index;
  switch (origin.source.field) {
    case PlanSource::Field::kProducer:
      return n.Child("heartbeat", spec_->heartbeat()).Warn("producer_ms", std::move(reason));
    case PlanSource::Field::kConsumer:
      return n.Child("heartbeat", spec_->heartbeat())
          .Child("consumer", spec_->heartbeat().consumer(k), k)
          .WarnHere(std::move(reason));
    case PlanSource::Field::kDcf:
      return n.Warn("dcf", std::move(reason));
    case PlanSource::Field::kSdo:
      break;
  }
  return n.Child("sdo", spec_->sdo(k), k).Warn("value", std::move(reason));
}

std::vector<ConfiguredPort> ConfigurePorts(const TopologyFacts& facts) {
  std::vector<ConfiguredPort> ports;
  const NodeIdLookup lookup = [&facts](const std::string& name, const std::string& bus) {
    std::optional<std::uint8_t> id;
    if (const NodeFacts* other = facts.FindNode(name)) {
      if (const auto on = other->IdOn(bus)) id = static_cast<std::uint8_t>(*on);
    }
    return id;
  };
  for (const NodeFacts& node : facts.nodes) {
    std::vector<std::uint8_t> ids;
    for (const std::uint32_t id : node.ids)
      ids.push_back(static_cast<std::uint8_t>(id));
    for (std::size_t p = 0; p < node.ports; ++p) {
      if (node.ids[p] == kUnconfiguredNodeId) continue;
      const Node& spec = facts.spec.node(node.index);
      ConfiguredPort port(node, spec, p);
      try {
        for (const PlannedWrite& write : PlanConfiguration(spec, node.buses, ids, p, lookup))
          port.Apply(write);
      } catch (const std::exception&) {
        // Loading has checked every value the plan encodes; a DCF that changed since is read
        // again when the fleet configures the node.
      }
      ports.push_back(std::move(port));
    }
  }
  return ports;
}

}  // namespace canfleet::topology::detail
