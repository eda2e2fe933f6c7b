#include "node/canopen/lss/lss_protocol.hpp"

namespace canfleet::canopen {

std::optional<std::uint32_t> BitRateKbit(std::uint8_t table_index) {
  // CiA 301 bit timing table as used by CiA 305 table selector 0.
  static constexpr std::array<std::uint32_t, 9> kTable{1000, 800, 500, 250, 125, 0, 50, 20, 10};
  if (table_index >= kTable.size() || kTable[table_index] == 0) return std::nullopt;
  return kTable[table_index];
}

CanFrame LssFrame(std::uint32_t id, LssCs cs, std::initializer_list<std::uint8_t> data) {
  CanFrame frame;
  frame.id = id;
  frame.dlc = 8;
  frame.data[0] = static_cast<std::uint8_t>(cs);
  std::size_t i = 1;
  for (auto byte : data) {
    if (i >= frame.data.size()) break;
    frame.data[i++] = byte;
  }
  return frame;
}

CanFrame LssFrame32(std::uint32_t id, LssCs cs, std::uint32_t value) {
  return LssFrame(id, cs,
                  {static_cast<std::uint8_t>(value), static_cast<std::uint8_t>(value >> 8),
                   static_cast<std::uint8_t>(value >> 16), static_cast<std::uint8_t>(value >> 24)});
}

}  // namespace canfleet::canopen
