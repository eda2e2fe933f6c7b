#include "node/process/bit_rate_commissioning.hpp"

#include "bus/broker_client/broker_client_port.hpp"
#include "node/canopen/lss/lss_protocol.hpp"

namespace canfleet::node {

namespace {

/// The CiA 305 table-0 index of a rate in bit/s (index 5, reserved, is never one).
std::optional<std::uint8_t> TableIndexOf(std::uint32_t bitrate) {
  if (bitrate == 0 || bitrate % 1000 != 0) return std::nullopt;
  for (std::uint8_t index = 0; index <= 8; ++index) {
    const auto kbit = canopen::BitRateKbit(index);
    if (kbit && *kbit * 1000 == bitrate) return index;
  }
  return std::nullopt;
}

}  // namespace

Commissioning CommissionFor(std::uint32_t stated, std::uint32_t bus_bitrate, std::uint8_t factory_index) {
  Commissioning out;
  if (stated != 0 || bus_bitrate == 0) return out;
  const auto index = TableIndexOf(bus_bitrate);
  if (!index) {
    out.message = "bus bit rate " + std::to_string(bus_bitrate) +
                  " bit/s has no CiA 305 table-0 index: the port runs at the bus's rate";
    return out;
  }
  out.adopted = index;
  if (*index != factory_index) {
    const auto factory = canopen::BitRateKbit(factory_index);
    out.message = "no bit rate configured: commissioned for the bus at " +
                  std::to_string(bus_bitrate / 1000) + " kbit/s (bit timing index " + std::to_string(*index) +
                  "; factory " + (factory ? std::to_string(*factory) + " kbit/s" : std::string("?")) + ")";
  }
  return out;
}

void CommissionBitRate(devices::DeviceNode& node, std::size_t p, BusPort& port,
                       const std::function<void(const std::string&)>& log) {
  auto* client = dynamic_cast<BrokerClientPort*>(&port);
  if (client == nullptr) return;
  const auto session = client->Session();
  if (!session) return;
  canopen::CanopenStack& stack = node.stack(p);
  const Commissioning c = CommissionFor(client->BitRate(), session->bitrate, stack.BitTimingIndex());
  if (c.adopted) {
    stack.AdoptBitTiming(*c.adopted);
    client->SetBitRate(session->bitrate);  // stated from now on, also to a broker met later
  }
  if (!c.message.empty() && log) log("CAN" + std::to_string(p + 1) + ": " + c.message);
}

void KeepFactoryBitRate(devices::DeviceNode& node, std::size_t p, BusPort& port,
                        const std::function<void(const std::string&)>& log) {
  auto* client = dynamic_cast<BrokerClientPort*>(&port);
  if (client == nullptr || client->BitRate() != 0) return;
  const auto kbit = canopen::BitRateKbit(node.stack(p).BitTimingIndex());
  if (!kbit) return;
  client->SetBitRate(*kbit * 1000);
  const auto session = client->Session();
  if (log && session && session->bitrate != *kbit * 1000)
    log("CAN" + std::to_string(p + 1) + ": factory bit rate " + std::to_string(*kbit) +
        " kbit/s kept on a bus at " + std::to_string(session->bitrate / 1000) +
        " kbit/s: no traffic until a master sets the rate");
}

}  // namespace canfleet::node
