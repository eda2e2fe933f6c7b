// Supply voltage and processor temperature of the AX023241 (1.5 "Fault Detection Objects",
// C3-1.4.63-1.4.69, 4.1): measured values, over/under voltage and over-temperature with their
// thresholds, persistence delays and hysteresis, the EMCY codes chosen for them (README.md), 1029h
// sub 6, and "ALL outputs" off while a fault is active.
#include <cstring>

#include "tests/unit/encoder/encoder_fixture.hpp"

namespace canfleet::devices::encoder::test {
namespace {

class SupplyTest : public EncoderTest {
 protected:
  double Real(std::uint16_t index, std::uint8_t sub) {
    const auto bits = static_cast<std::uint32_t>(Read(index, sub));
    float f = 0;
    std::memcpy(&f, &bits, sizeof f);
    return static_cast<double>(f);
  }
  /// Output 1 at 1000 mA under control source 0 (7330h), no ramps.
  void DriveOutput1() {
    Write(0x2330, 1, 0, 2);
    Write(0x2331, 1, 0, 2);
    Write(0x2340, 1, 0, 1);
    Write(0x7330, 1, 1000, 2);
    Advance(1ms);
    ASSERT_EQ(Out("OUT1.current_mA"), 1000);
  }
};

// C3-1.4.63-1.4.65: 5020h V, 5030h degC; 5040h in the thresholds' 0.1 units.
TEST_F(SupplyTest, MeasuredValues) {
  EXPECT_DOUBLE_EQ(Real(0x5020, 0), 24.0);
  EXPECT_DOUBLE_EQ(Real(0x5030, 0), 25.0);
  EXPECT_DOUBLE_EQ(Real(0x5040, 1), 250.0);
  EXPECT_DOUBLE_EQ(Real(0x5040, 2), 240.0);
  SetNumber("VPS.voltage_mV", 12500);
  Advance(1ms);
  EXPECT_DOUBLE_EQ(Real(0x5020, 0), 12.5);
  EXPECT_DOUBLE_EQ(Real(0x5040, 3), 125.0);
}

// 1.5: at 5041h.2 (50.0 V) for 5051h.2 x 100 ms (1 s) -> EMCY 3000h, 1003h 20003000h; all outputs
// off; the fault clears at 5042h.2 (48.0 V), not before.
TEST_F(SupplyTest, OverVoltageAfterItsDelaySwitchesOutputsOffUntilTheClearThreshold) {
  DriveOutput1();
  SetNumber("VPS.voltage_mV", 51000);
  Advance(1000ms);
  EXPECT_TRUE(Frames("085#").empty());
  EXPECT_EQ(Out("OUT1.current_mA"), 1000);
  Advance(1ms);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{Emcy(0x3000, 0, 0x20)});
  EXPECT_EQ(Read(0x1003, 1), 0x20003000);
  EXPECT_EQ(Out("OUT1.current_mA"), 0);
  SetNumber("VPS.voltage_mV", 49000);
  Advance(10ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 0);
  SetNumber("VPS.voltage_mV", 47500);
  Advance(1ms);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{"085#0000000000000000"});
  EXPECT_EQ(Out("OUT1.current_mA"), 1000);
}

// A value that leaves before its delay raises nothing; the device sleeps through the delay.
TEST_F(SupplyTest, ABriefExcursionIsNotAFault) {
  SetNumber("VPS.voltage_mV", 55000);
  Advance(1ms);
  const auto evaluations = device().Evaluations();
  Advance(500ms);
  EXPECT_EQ(device().Evaluations(), evaluations);
  SetNumber("VPS.voltage_mV", 24000);
  Advance(2000ms);
  EXPECT_TRUE(Frames("085#").empty());
  EXPECT_EQ(Read(0x1003, 0), 0);
}

// 5041h.3 = 9.0 V, clear 5042h.3 = 12.0 V -> 40003000h; 4.1: below 7.5 V the outputs are off at
// once (hardware), before any delay.
TEST_F(SupplyTest, UnderVoltageAndHardwareShutdown) {
  DriveOutput1();
  SetNumber("VPS.voltage_mV", 7000);
  Advance(1ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 0);
  SetNumber("VPS.voltage_mV", 8500);
  Advance(1ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 1000);  // 8.5 V / 8 ohm = 1062 mA: enough
  Advance(1000ms);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{Emcy(0x3000, 0, 0x40)});
  EXPECT_EQ(Read(0x1003, 1), 0x40003000);
  EXPECT_EQ(Out("OUT1.current_mA"), 0);
  SetNumber("VPS.voltage_mV", 11000);
  Advance(5ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 0);
  SetNumber("VPS.voltage_mV", 12000);
  Advance(1ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 1000);
}

// 1.5: "a microprocessor over-temperature reading disables all the outputs until it has cooled
// back to the operating range": 110.0 degC set, 85.0 degC clear -> 4200h, 1003h 20004200h, 1029h
// sub 6 (here 2 = stopped).
TEST_F(SupplyTest, OverTemperatureAppliesOtherFaultsBehaviour) {
  Write(0x1029, 6, 2, 1);
  Write(0x5051, 1, 0, 2);
  Start();
  SetNumber("TEMP.temperature_C", 112);
  Advance(1ms);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{Emcy(0x4200, 0, 0x20)});
  EXPECT_EQ(stack().State(), canopen::NmtState::kStopped);
  EXPECT_EQ(od().GetUnsigned(0x1003, 1), 0x20004200u);  // no SDO in stopped
  SetNumber("TEMP.temperature_C", 90);
  Advance(1ms);
  EXPECT_EQ(od().GetUnsigned(0x1001, 0), 1u);
  SetNumber("TEMP.temperature_C", 85);
  Advance(1ms);
  EXPECT_EQ(od().GetUnsigned(0x1001, 0), 0u);
}

// 5050h: bit 0 enables the supply checks, bit 1 the temperature check.
TEST_F(SupplyTest, DisabledChecksRaiseNothing) {
  Write(0x5050, 0, 0x02, 1);
  DriveOutput1();
  SetNumber("VPS.voltage_mV", 55000);
  Advance(2000ms);
  EXPECT_TRUE(Frames("085#").empty());
  EXPECT_EQ(Out("OUT1.current_mA"), 1000);
  Write(0x5050, 0, 0x00, 1);
  SetNumber("TEMP.temperature_C", 120);
  Advance(2000ms);
  EXPECT_TRUE(Frames("085#").empty());
}

}  // namespace
}  // namespace canfleet::devices::encoder::test
