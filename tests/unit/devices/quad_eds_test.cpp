// The Quad's EDS (node/devices/quad_controller/quad-controller.eds) against the manual
// AX020506 V2.02: it loads with the project's CiA 306 reader, holds exactly the objects the manual
// lists with their types, access, mapping and defaults, and the default PDOs of §3.1.1.
#include <gtest/gtest.h>

#include <set>

#include "node/canopen/eds/eds.hpp"
#include "node/devices/quad_controller/quad_controller.hpp"

namespace canfleet::devices {
namespace {

using canopen::Access;
using canopen::DataType;
using canopen::EdsFile;
using canopen::ObjectCode;

class QuadEdsTest : public ::testing::Test {
 protected:
  static const EdsFile& Eds() {
    static const EdsFile eds = canopen::ReadEds(CANFLEET_QUAD_EDS);
    return eds;
  }
  static std::uint64_t Default(std::uint16_t index, std::uint8_t sub) {
    const auto* s = Eds().od.Find(index, sub);
    EXPECT_NE(s, nullptr) << std::hex << index << "." << int{sub};
    return s ? canopen::DecodeUnsignedLe(s->default_value) : 0;
  }
  static const canopen::SubObject& Sub(std::uint16_t index, std::uint8_t sub) {
    const auto* s = Eds().od.Find(index, sub);
    if (!s) throw std::runtime_error("missing entry");
    return *s;
  }
};

// The compiled-in text is the file in the tree (users load the same file into their master).
TEST_F(QuadEdsTest, TheCompiledInTextIsTheShippedFile) {
  const EdsFile compiled = canopen::ParseEds(QuadControllerEds().Text(), "quad-controller.eds");
  EXPECT_TRUE(canopen::DiffEdsFiles(compiled, Eds(), canopen::EdsFormat::kEds).empty());
}

// §3.1 (communication objects), §3.2-§3.5 (application tables), §3.1.10 (5555h): every object
// the manual lists, and nothing else.
TEST_F(QuadEdsTest, HoldsExactlyTheObjectsTheManualLists) {
  std::set<std::uint16_t> expected = {
      0x1000, 0x1001, 0x1002, 0x1003, 0x100C, 0x100D, 0x1010, 0x1011, 0x1016, 0x1017, 0x1018, 0x1020, 0x1029,
      0x5555,
      // DI §3.2
      0x2000, 0x2001, 0x2002, 0x6000, 0x6002,
      // AI §3.3
      0x2010, 0x2020, 0x2030, 0x2040, 0x2050, 0x2060, 0x2070, 0x2080, 0x2090, 0x20A0, 0x20B0, 0x7100, 0x6110,
      0x6112, 0x7120, 0x7121, 0x7122, 0x7123, 0x7124, 0x6125, 0x7130, 0x6132, 0x61A0, 0x61A1,
      // DO §3.4
      0x3001, 0x3002, 0x300B, 0x300C, 0x6200, 0x6202, 0x6206, 0x6207,
      // AO §3.5
      0x3010, 0x3020, 0x3030, 0x3040, 0x3050, 0x3060, 0x3070, 0x3080, 0x3090, 0x30A0, 0x30B0, 0x30C0, 0x7300,
      0x6302, 0x6310, 0x7320, 0x7321, 0x7322, 0x7323, 0x7330, 0x6340, 0x7341, 0x7F50, 0x6F52};
  for (std::uint16_t i = 0; i < 4; ++i) {
    for (int base : {0x1400, 0x1600, 0x1800, 0x1A00})
      expected.insert(static_cast<std::uint16_t>(base + i));
  }
  std::set<std::uint16_t> actual;
  for (const auto& [index, object] : Eds().od.objects())
    actual.insert(index);
  EXPECT_EQ(actual, expected);
}

// §3.1.2, §3.1.8 and the LSS support of §2.1.
TEST_F(QuadEdsTest, IdentityAndDeviceInfo) {
  EXPECT_EQ(Default(0x1000, 0), 0x000F0194u);
  EXPECT_EQ(Default(0x1018, 1), 0x00000055u);
  EXPECT_EQ(Default(0x1018, 2), 0xAA020502u);
  const auto& info = Eds().device_info;
  EXPECT_TRUE(info.lss_supported);
  EXPECT_EQ(info.vendor_number, 0x55u);
  EXPECT_EQ(info.product_number, 0xAA020502u);
  EXPECT_EQ(info.nr_of_rx_pdo, 4);
  EXPECT_EQ(info.nr_of_tx_pdo, 4);
  EXPECT_EQ(info.granularity, 8);  // §3.1.1 "The granularity is 8-bits"
}

// §3.1.4: up to 16 errors, sub 0 = number of errors (written 0 to clear the list).
TEST_F(QuadEdsTest, ErrorFieldHoldsSixteenEntries) {
  const auto& field = *Eds().od.Find(0x1003);
  EXPECT_EQ(field.code, ObjectCode::kArray);
  EXPECT_EQ(field.subs.size(), 17u);
  EXPECT_EQ(Sub(0x1003, 0).access, Access::kRw);
  EXPECT_EQ(Default(0x1003, 0), 0u);
  for (std::uint8_t i = 1; i <= 16; ++i) {
    EXPECT_EQ(Sub(0x1003, i).type, DataType::kUnsigned32);
    EXPECT_EQ(Sub(0x1003, i).access, Access::kRo);
  }
}

// §3.1.7: four consumer entries; §3.1.9: 1029h with 5 entries, 0 for communication, 1 else.
TEST_F(QuadEdsTest, HeartbeatConsumersAndErrorBehaviour) {
  EXPECT_EQ(Default(0x1016, 0), 4u);
  for (std::uint8_t i = 1; i <= 4; ++i)
    EXPECT_EQ(Default(0x1016, i), 0u);
  EXPECT_FALSE(Eds().od.Find(0x1016, 5));
  EXPECT_EQ(Default(0x1029, 0), 5u);
  EXPECT_EQ(Default(0x1029, 1), 0u);
  for (std::uint8_t i = 2; i <= 5; ++i)
    EXPECT_EQ(Default(0x1029, i), 1u);
  EXPECT_EQ(canopen::DecodeUnsignedLe(*Sub(0x1029, 1).high_limit), 2u);
}

// §3.1.1: RPDOs type 255 on 200h/300h/400h/500h + node-ID; TPDOs type 254 on 180h/280h/380h/480h +
// node-ID with event timer 100 ms; mappings as the tables give them.
TEST_F(QuadEdsTest, DefaultPdosAreThoseOfSection311) {
  const std::uint32_t rpdo_base[] = {0x200, 0x300, 0x400, 0x500};
  const std::uint32_t tpdo_base[] = {0x180, 0x280, 0x380, 0x480};
  for (std::uint8_t n = 0; n < 4; ++n) {
    const auto& rcob = Sub(static_cast<std::uint16_t>(0x1400 + n), 1);
    EXPECT_TRUE(rcob.default_adds_node_id);
    EXPECT_EQ(canopen::DecodeUnsignedLe(rcob.default_value), rpdo_base[n]);
    EXPECT_EQ(Default(static_cast<std::uint16_t>(0x1400 + n), 2), 255u);
    EXPECT_EQ(Default(static_cast<std::uint16_t>(0x1400 + n), 5), 0u);
    const auto& tcob = Sub(static_cast<std::uint16_t>(0x1800 + n), 1);
    EXPECT_TRUE(tcob.default_adds_node_id);
    EXPECT_EQ(canopen::DecodeUnsignedLe(tcob.default_value), tpdo_base[n]);
    EXPECT_EQ(Default(static_cast<std::uint16_t>(0x1800 + n), 2), 254u);
    EXPECT_EQ(Default(static_cast<std::uint16_t>(0x1800 + n), 5), 100u);
  }
  const std::vector<std::vector<std::uint32_t>> rpdo_maps = {
      {0x73300110, 0x73300210, 0x73300310, 0x73300410}, {0x62000108}, {}, {}};
  const std::vector<std::vector<std::uint32_t>> tpdo_maps = {
      {0x71000110, 0x71000210, 0x71000310, 0x71000410},
      {0x71000510, 0x71000610},
      {0x60000108, 0x300C0108},
      {0x30C00110, 0x30C00210, 0x30C00310, 0x30C00410}};
  for (std::uint8_t n = 0; n < 4; ++n) {
    for (auto [base, maps] : {std::pair{0x1600, &rpdo_maps}, std::pair{0x1A00, &tpdo_maps}}) {
      const auto index = static_cast<std::uint16_t>(base + n);
      const auto& map = (*maps)[n];
      EXPECT_EQ(Default(index, 0), map.size()) << std::hex << index;
      for (std::uint8_t i = 1; i <= 4; ++i)
        EXPECT_EQ(Default(index, i), i <= map.size() ? map[i - 1u] : 0u)
            << std::hex << index << "." << int{i};
    }
  }
}

// Table rows of §3.2-§3.5 where the manual contradicts itself (README.md): 30A0h UNSIGNED8,
// 30C0h read-only; and the mapping/access columns the PDO defaults rely on.
TEST_F(QuadEdsTest, TypesAccessAndMappingOfApplicationObjects) {
  EXPECT_EQ(Sub(0x30A0, 1).type, DataType::kUnsigned8);
  EXPECT_EQ(Sub(0x30C0, 1).access, Access::kRo);
  EXPECT_TRUE(Sub(0x30C0, 1).pdo_mappable);
  EXPECT_EQ(Sub(0x6125, 6).access, Access::kWo);
  EXPECT_EQ(Sub(0x7100, 1).type, DataType::kInteger16);
  EXPECT_EQ(Sub(0x7100, 1).access, Access::kRo);
  EXPECT_TRUE(Sub(0x7100, 6).pdo_mappable);
  EXPECT_TRUE(Sub(0x7330, 4).pdo_mappable);
  EXPECT_TRUE(canopen::IsWritable(Sub(0x7330, 4).access));
  EXPECT_TRUE(Sub(0x6200, 1).pdo_mappable);
  EXPECT_TRUE(Sub(0x2090, 2).pdo_mappable);
  EXPECT_FALSE(Sub(0x7300, 1).pdo_mappable);
  EXPECT_EQ(Sub(0x5555, 0).type, DataType::kBoolean);
  // Per-input defaults differ between AIN (mV) and FIN (0.01 %), §3.2.2-3, §3.3.1-8.
  EXPECT_EQ(Default(0x2010, 4), 200u);
  EXPECT_EQ(Default(0x2010, 5), 100u);
  EXPECT_EQ(Default(0x2080, 1), 4800u);
  EXPECT_EQ(Default(0x2080, 6), 9900u);
  EXPECT_EQ(Default(0x6110, 1), 40u);
  EXPECT_EQ(Default(0x6110, 5), 10000u);
  EXPECT_EQ(Default(0x2000, 1), 0x3Fu);
  EXPECT_EQ(Default(0x6206, 1), 0x1Fu);
  EXPECT_EQ(Default(0x30A0, 1), 2u);
  EXPECT_EQ(Default(0x3080, 1), 1500u);
  EXPECT_EQ(Default(0x6340, 1), 1u);
}

}  // namespace
}  // namespace canfleet::devices
