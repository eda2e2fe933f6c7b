// Supply voltage and processor temperature monitoring (UMAX020411A §1.10, §3.4.99-3.4.107, Table 33):
// 40003000h / 20003000h with the 5024h hysteresis, the over-temperature entry (README: 20004200h),
// and the supply fault's hardware shutdown of the outputs (§4).
#include "tests/unit/valve/valve_fixture.hpp"

namespace canfleet::devices::valve::test {
namespace {

constexpr std::uint32_t kTooHigh = 0x06090031;
constexpr std::uint32_t kTooLow = 0x06090032;

class ValveMonitorTest : public ValveTest {
 protected:
  void Supply(double volts) {
    SetNumber("VPS.voltage_mV", volts * 1000);
    Advance(2ms);
  }
};

// §3.4.101, §3.4.103: below 5022h (8 V) -> 40003000h; cleared at 5022h + 5024h (13 V).
TEST_F(ValveMonitorTest, UnderVoltage) {
  Supply(7.5);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{Emcy(0x3000, 0x01, 0, 0x40)});
  EXPECT_EQ(Read(0x1003, 1), 0x40003000);
  EXPECT_EQ(Read(0x5020, 0), 0x40F00000);  // 7.5 V, REAL32
  Supply(12);
  EXPECT_EQ(Read(0x1003, 0), 1);
  Supply(13);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{EmcyReset()});
  EXPECT_EQ(Read(0x1003, 0), 0);
}

// §3.4.102: above 5023h (35 V) -> 20003000h; cleared at 5023h - 5024h (30 V).
TEST_F(ValveMonitorTest, OverVoltage) {
  Supply(36);
  EXPECT_EQ(Read(0x1003, 1), 0x20003000);
  Supply(31);
  EXPECT_EQ(Read(0x1003, 0), 1);
  Supply(30);
  EXPECT_EQ(Read(0x1003, 0), 0);
}

// §3.4.100: 5021h FALSE: no supply fault.
TEST_F(ValveMonitorTest, SupplyDetectionDisabled) {
  Write(0x5021, 0, 0, 1);
  Supply(5);
  EXPECT_TRUE(Frames("085#").empty());
}

// §4 "Under-voltage Protection Provided (hardware shutdown)": outputs off during a supply fault.
TEST_F(ValveMonitorTest, SupplyFaultShutsTheOutputsOff) {
  Write(0x2330, 1, 0, 2);
  SilenceTpdos();
  Start();
  Send("205#8403000000000000");  // 7300h.1 = 900
  Advance(2ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 900);
  Supply(6);
  EXPECT_EQ(Out("OUT1.current_mA"), 0);
  Supply(24);
  EXPECT_EQ(Out("OUT1.current_mA"), 900);
}

// §3.4.105-3.4.107, §4 "Diagnostics ... an Over Temperature fault": above 5032h (85 degC) ->
// 20004200h (no code in Table 33: README); cleared at 5032h - 5033h (60 degC).
TEST_F(ValveMonitorTest, OverTemperature) {
  SetNumber("TEMP.temperature_C", 90);
  Advance(2ms);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{Emcy(0x4200, 0x01, 0, 0x20)});
  EXPECT_EQ(Read(0x1003, 1), 0x20004200);
  SetNumber("TEMP.temperature_C", 61);
  Advance(2ms);
  EXPECT_EQ(Read(0x1003, 0), 1);
  SetNumber("TEMP.temperature_C", 60);
  Advance(2ms);
  EXPECT_EQ(Read(0x1003, 0), 0);
}

// §3.4.101/3.4.102: 5022h <= 5023h, 5023h <= 36 V.
TEST_F(ValveMonitorTest, ThresholdRanges) {
  Refused(0x5022, 0, 36, 1, kTooHigh);
  Refused(0x5023, 0, 7, 1, kTooLow);
  Refused(0x5023, 0, 37, 1, kTooHigh);
  Write(0x5022, 0, 10, 1);
}

}  // namespace
}  // namespace canfleet::devices::valve::test
