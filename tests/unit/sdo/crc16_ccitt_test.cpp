// CRC of SDO block transfers, CiA 301 v4.2 §7.2.4.3.16 (CRC-16-CCITT, XMODEM variant).
#include "node/canopen/sdo/crc16_ccitt.hpp"

#include <gtest/gtest.h>

#include <string_view>

#include "node/canopen/od/value.hpp"

namespace canfleet::canopen {
namespace {

TEST(Crc16Ccitt, CheckValueOf123456789Is31C3) {
  EXPECT_EQ(Crc16Ccitt(ToBytes("123456789")), 0x31C3);
}

TEST(Crc16Ccitt, EmptyDataGivesTheInitialValueZero) {
  EXPECT_EQ(Crc16Ccitt({}), 0x0000);
}

TEST(Crc16Ccitt, ContinuesAcrossPieces) {
  const auto whole = ToBytes("123456789");
  const auto first = Crc16Ccitt(std::span(whole).first(4));
  EXPECT_EQ(Crc16Ccitt(std::span(whole).subspan(4), first), 0x31C3);
}

TEST(Crc16Ccitt, KnownValuesOfSingleBytes) {
  // Bitwise reference: poly 1021h, MSB first, init 0.
  for (unsigned b = 0; b < 256; ++b) {
    unsigned crc = b << 8;
    for (int i = 0; i < 8; ++i)
      crc = (crc & 0x8000u) ? (crc << 1) ^ 0x1021u : crc << 1;
    const std::uint8_t byte = static_cast<std::uint8_t>(b);
    EXPECT_EQ(Crc16Ccitt(std::span(&byte, 1)), static_cast<std::uint16_t>(crc)) << b;
  }
}

}  // namespace
}  // namespace canfleet::canopen
