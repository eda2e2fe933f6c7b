// Supply voltage and processor temperature of the data logger (UMAX181001 §1.8, §3.4.68-3.4.76,
// Table 26), the 1003h depth (§3.2.4) and the default objects (§3.2, §3.4.67).

#include <cstring>

#include "node/devices/datalogger_tc_analog/datalogger_objects.hpp"
#include "tests/unit/datalogger/datalogger_fixture.hpp"

namespace canfleet::devices::test {
namespace {

using namespace datalogger;

class DiagTest : public DataLoggerTest {
 protected:
  DiagTest() { ConfigureTcLimitsAway(); }
  float Real32(int port, std::uint16_t index, std::uint8_t sub = 0) {
    const auto raw = static_cast<std::uint32_t>(Read(port, index, sub));
    float f;
    std::memcpy(&f, &raw, sizeof f);
    return f;
  }
};

// §3.4.68-3.4.72, Table 26: 5020h reads the supply; above 5023h (35 V) 20003000h, cleared at
// 5023h - 5024h (30 V); below 5022h (8 V) 40003000h, cleared at 5022h + 5024h (13 V).
TEST_F(DiagTest, SupplyOverAndUnderVoltage) {
  Advance(10ms);
  EXPECT_FLOAT_EQ(Real32(0, kSupplyValue), 24.0f);
  SetNumber("VPS.voltage_mV", 36000);
  Advance(10ms);
  EXPECT_EQ(Frames(0, "085#"), std::vector<std::string>{Emcy(kNode1, 0x3000, 0x01, 0x00, 0x20)});
  SetNumber("VPS.voltage_mV", 31000);
  Advance(10ms);
  EXPECT_EQ(ErrorField(0), std::vector<std::uint32_t>{0x20003000});
  SetNumber("VPS.voltage_mV", 30000);
  Advance(10ms);
  EXPECT_TRUE(ErrorField(0).empty());
  SetNumber("VPS.voltage_mV", 7500);
  Advance(10ms);
  EXPECT_EQ(ErrorField(1), std::vector<std::uint32_t>{0x40003000});
  SetNumber("VPS.voltage_mV", 12000);
  Advance(10ms);
  EXPECT_EQ(ErrorField(1), std::vector<std::uint32_t>{0x40003000});  // 12 < 8 + 5
  SetNumber("VPS.voltage_mV", 13000);
  Advance(10ms);
  EXPECT_TRUE(ErrorField(1).empty());
  // §3.4.69: 5021h FALSE ignores the thresholds.
  Write(0, kSupplyErrorEnable, 0, 0, 1);
  SetNumber("VPS.voltage_mV", 48000);  // a 48 V system: above the highest settable 5023h (36 V)
  Advance(10ms);
  EXPECT_TRUE(ErrorField(0).empty());
}

// §3.4.70-71: 5022h <= 5023h; 5023h at most 36 V.
TEST_F(DiagTest, SupplyThresholdRules) {
  EXPECT_EQ(TryWrite(0, kUnderVoltage, 0, 36, 1), SdoAborted(kNode1, kUnderVoltage, 0, 0x06090031));
  EXPECT_EQ(TryWrite(0, kOverVoltage, 0, 37, 1), SdoAborted(kNode1, kOverVoltage, 0, 0x06090031));
  EXPECT_EQ(TryWrite(0, kOverVoltage, 0, 7, 1), SdoAborted(kNode1, kOverVoltage, 0, 0x06090032));
  Write(0, kOverVoltage, 0, 36, 1);
}

// §3.4.73-3.4.76: above 5032h (85 C) an over-temperature fault, cleared at 5032h - 5033h (60 C).
// Table 26 has no code for it: 20004200h (README choice), on both ports.
TEST_F(DiagTest, ProcessorOverTemperature) {
  SetNumber("TEMP.temperature_C", 86);
  Advance(10ms);
  EXPECT_FLOAT_EQ(Real32(1, kCpuTemperature), 86.0f);
  EXPECT_EQ(Frames(1, "086#"), std::vector<std::string>{Emcy(kNode2, 0x4200, 0x01, 0x00, 0x20)});
  SetNumber("TEMP.temperature_C", 61);
  Advance(10ms);
  EXPECT_EQ(ErrorField(0), std::vector<std::uint32_t>{0x20004200});
  SetNumber("TEMP.temperature_C", 60);
  Advance(10ms);
  EXPECT_TRUE(ErrorField(0).empty());
}

// §3.2.4: "a maximum of 4 errors in the list ... the oldest entries will be lost"; an entry
// leaves the list when its error clears; writing 0 to sub 0 empties the list but 1001h stays.
TEST_F(DiagTest, ErrorFieldKeepsFourAndClearsOnWrite) {
  Write(0, kAiErrorEnable, 1, 1, 1);
  Write(0, kAiErrorDelay, 1, 0, 2);
  SetNumber("VPS.voltage_mV", 40000);
  SetNumber("TEMP.temperature_C", 90);
  SetBool("TC1.open", true);
  SetBool("TC2.open", true);
  SetNumber("IN1.voltage_mV", 0);
  Advance(400ms);
  EXPECT_EQ(ErrorField(0).size(), 4u);
  // No 5th entry (README C8): a read past the count answers "no data available".
  EXPECT_EQ(Sdo(0, SdoRead(kNode1, 0x1003, 5)), SdoAborted(kNode1, 0x1003, 5, 0x08000024));
  Write(0, 0x1003, 0, 0, 1);
  EXPECT_TRUE(ErrorField(0).empty());
  EXPECT_EQ(Read(0, 0x1001, 0), 1);
  EXPECT_EQ(ErrorField(1).size(), 4u);  // the other port's list is its own
}

// §3.2.15: TPDO7 (1A06h) maps 5020h and 5030h (REAL32); not valid by default. Enabled on CAN2
// (COB-ID 381h + 1 + node 6 = 387h) it carries 24.0 V and 35.0 C.
TEST_F(DiagTest, Tpdo7CarriesSupplyAndTemperature) {
  Write(1, 0x1806, 1, 0x40000387, 4);
  Write(1, 0x1806, 5, 100, 2);
  Start(1);
  Advance(100ms);
  EXPECT_EQ(Frames(1, "387#"), std::vector<std::string>{"387#0000C04100000C42"});
  EXPECT_TRUE(Frames(0, "387#").empty());
}

// §3.4.67: 5010h constants, REAL32; sub 1/2 read-only FALSE/TRUE, 3-15 the printed values.
TEST_F(DiagTest, Constants) {
  EXPECT_FLOAT_EQ(Real32(0, kConstantValue, 1), 0.0f);
  EXPECT_FLOAT_EQ(Real32(1, kConstantValue, 2), 1.0f);
  EXPECT_FLOAT_EQ(Real32(0, kConstantValue, 3), 3.141593f);
  EXPECT_FLOAT_EQ(Real32(0, kConstantValue, 15), 100.0f);
  EXPECT_EQ(TryWrite(0, kConstantValue, 1, 0x3F800000, 4), SdoAborted(kNode1, kConstantValue, 1, 0x06010002));
}

}  // namespace
}  // namespace canfleet::devices::test
