#include "orchestrator/topology/configuration_plan.hpp"

#include <stdexcept>

#include "node/canopen/eds/eds_reader.hpp"
#include "orchestrator/control/sdo_value.hpp"

namespace canfleet::topology {

namespace {

std::vector<std::uint8_t> Le(std::uint32_t value, std::size_t bytes) {
  std::vector<std::uint8_t> out(bytes);
  for (std::size_t i = 0; i < bytes; ++i)
    out[i] = static_cast<std::uint8_t>(value >> (8 * i));
  return out;
}

}  // namespace

std::vector<PlannedWrite> PlanConfiguration(const Node& node, const std::vector<std::string>& buses,
                                            const std::vector<std::uint8_t>& node_ids, std::size_t port,
                                            const NodeIdLookup& lookup) {
  std::vector<PlannedWrite> plan;
  const std::string& bus = buses.at(port);
  const auto& hb = node.heartbeat();
  if (hb.producer_ms() > 0) {
    if (hb.producer_ms() > 0xFFFF) throw std::invalid_argument("heartbeat producer_ms above 65535");
    plan.push_back({0x1017,
                    0,
                    Le(hb.producer_ms(), 2),
                    "1017h heartbeat producer " + std::to_string(hb.producer_ms()) + " ms",
                    {PlanSource::Field::kProducer}});
  }
  std::uint8_t sub = 1;
  for (int k = 0; k < hb.consumer_size(); ++k) {
    const auto& consumer = hb.consumer(k);
    std::uint32_t id = consumer.node_id();
    if (!consumer.node().empty()) {
      const auto found = lookup(consumer.node(), bus);
      if (!found) {
        // A multi-port device consumes each node on the port whose bus carries it.
        if (buses.size() > 1) continue;
        throw std::invalid_argument("heartbeat consumer: node '" + consumer.node() + "' is not on bus " +
                                    bus);
      }
      id = *found;
    }
    // CiA 301 §7.5.2.28 (1016h): bits 16..23 node-ID, bits 0..15 heartbeat time in ms.
    const std::uint32_t entry = (id << 16) | (consumer.timeout_ms() & 0xFFFF);
    plan.push_back({0x1016,
                    sub,
                    Le(entry, 4),
                    "1016h." + std::to_string(sub) + " consume node " + std::to_string(id) + " heartbeat, " +
                        std::to_string(consumer.timeout_ms()) + " ms",
                    {PlanSource::Field::kConsumer, k}});
    ++sub;
  }
  if (!node.dcf().empty() && port == 0) {
    // CiA 306 §5: a DCF is the device's configuration; the master downloads what differs from
    // the device's defaults (its ParameterValues), writable entries only, in index order.
    const auto dcf = canopen::ReadEds(node.dcf());
    const std::uint8_t id = node_ids.at(port);
    for (const auto& [index, object] : dcf.od.objects()) {
      for (const auto& [sub_index, entry] : object.subs) {
        const auto a = entry.access;
        const bool writable = a == canopen::Access::kRw || a == canopen::Access::kWo ||
                              a == canopen::Access::kRwr || a == canopen::Access::kRww;
        if (!writable || entry.value == entry.DefaultFor(id)) continue;
        char where[48];
        std::snprintf(where, sizeof where, "%04Xh.%u from the DCF", index, sub_index);
        plan.push_back({index, sub_index, entry.value, where, {PlanSource::Field::kDcf}});
      }
    }
  }
  for (int k = 0; k < node.sdo_size(); ++k) {
    const auto& write = node.sdo(k);
    if (write.port() != port) continue;
    auto encoded = control::EncodeSdoValue(write.type(), write.value());
    char where[16];
    std::snprintf(where, sizeof where, "%04Xh.%u", write.index(), write.subindex());
    plan.push_back({static_cast<std::uint16_t>(write.index()),
                    static_cast<std::uint8_t>(write.subindex()),
                    std::move(encoded),
                    std::string(where) + " = " + write.type() + " " + write.value(),
                    {PlanSource::Field::kSdo, k}});
  }
  return plan;
}

}  // namespace canfleet::topology
