// The physics of the PS-24-24-350W-CAN (UMAX080311 §1.2.1.3, §3): current limit (Fig. 2, Table 3,
// 2330h), regulation, load, hardware input protection, the input filter (Table 4, 2100h/2101h),
// and the measured objects 6113h, 6204h, 6020h that come from them; and that an idle node does
// not tick (design decision 10).
#include "node/devices/power_supply_24v_350w/power_model.hpp"
#include "tests/unit/power_supply/ps_fixture.hpp"

namespace canfleet::devices::test {
namespace {

using ps::InputProtection;
using ps::Load;
using ps::ManufacturerCurrentLimit;
using ps::Operate;

// §1.2.1.3, Fig. 2: "When input voltage is >18V, the current limit is set to max (15A). When input
// voltage is <18V, the current limit varies linearly" along y = 0.8455x - 0.2805.
TEST(PsCurrentLimitCurve, Fig2) {
  EXPECT_DOUBLE_EQ(ManufacturerCurrentLimit(24.0), 15.0);
  EXPECT_DOUBLE_EQ(ManufacturerCurrentLimit(18.0), 15.0);
  EXPECT_NEAR(ManufacturerCurrentLimit(15.5), 12.82475, 1e-9);
  EXPECT_NEAR(ManufacturerCurrentLimit(10.0), 8.1745, 1e-9);
  EXPECT_DOUBLE_EQ(ManufacturerCurrentLimit(0.2), 0.0);  // the line crosses 0 A at 0.33 V
}

// §3: 24 V ±2 % from 11 V input, 23-24 V at 10-11 V input; above the limit, constant current;
// a short circuit delivers the limit at 0 V; the input current follows 94 % efficiency.
TEST(PsOperatingPoint, RegulationLoadAndLimit) {
  const Load ohm24{true, 24.0, 0.0};
  auto p = Operate(true, 24.0, 24.0, 15.0, ohm24);
  EXPECT_DOUBLE_EQ(p.voltage_V, 24.0);
  EXPECT_DOUBLE_EQ(p.current_A, 1.0);
  EXPECT_FALSE(p.current_limited);
  EXPECT_NEAR(p.input_current_A, 24.0 / (0.94 * 24.0), 1e-12);
  EXPECT_DOUBLE_EQ(Operate(true, 24.0, 10.5, 15.0, ohm24).voltage_V, 23.5);
  EXPECT_DOUBLE_EQ(Operate(true, 24.0, 10.0, 15.0, ohm24).voltage_V, 23.0);
  EXPECT_DOUBLE_EQ(Operate(true, 12.0, 10.0, 15.0, ohm24).voltage_V, 12.0);  // a buck needs no droop

  p = Operate(true, 24.0, 24.0, 15.0, Load{true, 1.0, 0.0});
  EXPECT_TRUE(p.current_limited);
  EXPECT_DOUBLE_EQ(p.current_A, 15.0);
  EXPECT_DOUBLE_EQ(p.voltage_V, 15.0);
  p = Operate(true, 24.0, 24.0, 15.0, Load{true, 0.0, 0.0});
  EXPECT_DOUBLE_EQ(p.voltage_V, 0.0);
  EXPECT_DOUBLE_EQ(p.current_A, 15.0);

  p = Operate(true, 24.0, 24.0, 15.0, Load{false, 0.0, 10.0});
  EXPECT_DOUBLE_EQ(p.voltage_V, 24.0);
  EXPECT_DOUBLE_EQ(p.current_A, 10.0);
  p = Operate(true, 24.0, 24.0, 15.0, Load{false, 0.0, 20.0});
  EXPECT_TRUE(p.current_limited);
  EXPECT_DOUBLE_EQ(p.current_A, 15.0);
  EXPECT_DOUBLE_EQ(p.voltage_V, 18.0);

  p = Operate(false, 24.0, 24.0, 15.0, ohm24);
  EXPECT_DOUBLE_EQ(p.voltage_V, 0.0);
  EXPECT_DOUBLE_EQ(p.current_A, 0.0);
}

// §3: "Undervoltage Protection: Shutdown at 8.5 VDC, Recovers at 11.5 VDC"; "Overvoltage
// Protection: Shutdown at 44 VDC, Recovers at 42 VDC".
TEST(PsInputProtection, ShutdownAndRecoveryThresholds) {
  InputProtection p;
  p.Reset(24.0);
  EXPECT_TRUE(p.Ok());
  EXPECT_EQ(p.Update(8.6), InputProtection::State::kOk);
  EXPECT_EQ(p.Update(8.4), InputProtection::State::kUnderVoltage);
  EXPECT_EQ(p.Update(11.4), InputProtection::State::kUnderVoltage);
  EXPECT_EQ(p.Update(11.5), InputProtection::State::kOk);
  EXPECT_EQ(p.Update(44.0), InputProtection::State::kOk);
  EXPECT_EQ(p.Update(44.1), InputProtection::State::kOverVoltage);
  EXPECT_EQ(p.Update(42.1), InputProtection::State::kOverVoltage);
  EXPECT_EQ(p.Update(42.0), InputProtection::State::kOk);
  p.Reset(9.0);  // powered up between the levels: running
  EXPECT_TRUE(p.Ok());
  p.Reset(5.0);
  EXPECT_FALSE(p.Ok());
}

class PsModelTest : public PsTest {
 protected:
  /// 6112h logic "not configured" for every flag: the CiA 453 input checks stay out of the way.
  void NoInputChecks() { Write(0x6112, 2, 0xFFFFFFFF, 4); }
  /// 6202h logic "not configured": no output failures (to watch the current limit for long).
  void NoOutputChecks() { Write(0x6202, 2, 0xFFFFFFFF, 4); }
};

// §1.2.3, §2.3.4, §2.3.10, §2.3.19: reported values come from the model in mV, mA and 0.1 degC.
TEST_F(PsModelTest, MeasuredObjectsFollowTheModel) {
  EXPECT_EQ(Read(0x6113, 1), 24000);
  EXPECT_EQ(Read(0x6020, 0), 250);
  EXPECT_EQ(Read(0x6204, 1), 0);
  SetNumber("TEMP.temperature_C", -12.34);
  Advance(1ms);
  EXPECT_EQ(Read(0x6020, 0, true), -123);
  OnByCan();
  Advance(1ms);
  EXPECT_EQ(Read(0x6204, 1), 24000);
  EXPECT_EQ(Read(0x6204, 2), 1000);
  EXPECT_NEAR(io().Number("IIN.current_mA"), 1064, 0.5);
  // §2.3.20: 6205h.1 sets the output voltage (README choice 7).
  Write(0x6205, 1, 12000, 4);
  Advance(2ms);
  EXPECT_DOUBLE_EQ(io().Number("VOUT.voltage_mV"), 12000);
  EXPECT_EQ(Read(0x6204, 1), 12000);
  EXPECT_EQ(Read(0x6204, 2), 500);
}

// §3 "23 to 24 VDC @ 10 to 11 VDC input".
TEST_F(PsModelTest, LowInputLowersTheOutputCeiling) {
  NoInputFilter();
  OnByCan();
  SetNumber("VIN.voltage_mV", 10500);
  Advance(2ms);
  EXPECT_DOUBLE_EQ(io().Number("VOUT.voltage_mV"), 23500);
  EXPECT_EQ(Read(0x6113, 1), 10500);
  EXPECT_EQ(Read(0x6204, 1), 23500);
}

// Table 3, 2330h = 0: the limit follows the measured input along Fig. 2; a 1 ohm load at 24 V
// input asks 24 A and gets 15 A at 15 V (constant current).
TEST_F(PsModelTest, ManufacturerCurrentLimitFollowsTheInput) {
  NoInputFilter();
  NoOutputChecks();
  SetNumber("LOAD.resistance_ohm", 1.0);
  OnByCan();
  Advance(1ms);
  EXPECT_TRUE(io().Bool("PS.current_limited"));
  EXPECT_DOUBLE_EQ(io().Number("PS.current_limit_mA"), 15000);
  EXPECT_EQ(Read(0x6204, 2), 15000);
  EXPECT_EQ(Read(0x6204, 1), 15000);
  SetNumber("VIN.voltage_mV", 15500);
  Advance(2ms);
  EXPECT_EQ(Read(0x6204, 2), 12825);  // 0.8455 × 15.5 − 0.2805 = 12.82475 A
  EXPECT_DOUBLE_EQ(io().Number("PS.current_limit_mA"), 12825);
  // 6201h.1 bits 3-2 and 6011h.1 bits 11-10: current limit (README choice 17).
  EXPECT_EQ(Read(0x6201, 1), 0x05);
  EXPECT_EQ(Read(0x6011, 1) & 0xC00, 0x400);
}

// Table 3, 2330h = 1: "The current limit ... can be set using object 6205h PS Output Set Values
// (subindex 8: set current). This value does not change in response to any input changes."
TEST_F(PsModelTest, Ds453CurrentLimitIs6205hSub8) {
  NoInputFilter();
  NoOutputChecks();
  Write(0x2330, 0, 1, 1);
  Write(0x6205, 8, 5000, 4);
  SetEnum("LOAD.mode", "current");
  SetNumber("LOAD.current_mA", 8000);
  OnByCan();
  Advance(1ms);
  EXPECT_EQ(Read(0x6204, 2), 5000);
  EXPECT_EQ(Read(0x6204, 1), 15000);  // 24 V × 5 A / 8 A
  SetNumber("VIN.voltage_mV", 12000);
  Advance(2ms);
  EXPECT_EQ(Read(0x6204, 2), 5000);
}

// §3: the hardware protection switches the output off at once below 8.5 V and lets it run again
// from 11.5 V; above 44 V off, from 42 V on. It is independent of the CiA 453 thresholds (here not
// configured) and sends no EMCY.
TEST_F(PsModelTest, HardwareUnderAndOverVoltageProtection) {
  NoInputFilter();
  NoInputChecks();
  OnByCan();
  SetNumber("VIN.voltage_mV", 8400);
  Advance(1ms);
  EXPECT_FALSE(io().Bool("PS.output_on"));
  EXPECT_EQ(State(), "protection");
  EXPECT_EQ(io().Enum("PS.protection"), "undervoltage");
  SetNumber("VIN.voltage_mV", 11400);
  Advance(5ms);
  EXPECT_FALSE(io().Bool("PS.output_on"));
  SetNumber("VIN.voltage_mV", 11500);
  Advance(1ms);
  EXPECT_TRUE(io().Bool("PS.output_on"));
  EXPECT_EQ(State(), "on");
  SetNumber("VIN.voltage_mV", 45000);
  Advance(1ms);
  EXPECT_EQ(io().Enum("PS.protection"), "overvoltage");
  EXPECT_FALSE(io().Bool("PS.output_on"));
  SetNumber("VIN.voltage_mV", 42500);
  Advance(5ms);
  EXPECT_FALSE(io().Bool("PS.output_on"));
  SetNumber("VIN.voltage_mV", 42000);
  Advance(1ms);
  EXPECT_TRUE(io().Bool("PS.output_on"));
  EXPECT_TRUE(Frames("0FF#").empty());
}

// Table 4: no filter, "Value = Input" at the next sample.
TEST_F(PsModelTest, InputFilterNone) {
  NoInputFilter();
  SetNumber("VIN.voltage_mV", 20000);
  Advance(1ms);
  EXPECT_EQ(Read(0x6113, 1), 20000);
}

// Table 4: moving average V_n = V_n-1 + (Input − V_n-1) / 2101h.
TEST_F(PsModelTest, InputFilterMovingAverage) {
  Write(0x2100, 1, 1, 1);
  Write(0x2101, 1, 2, 2);
  SetNumber("VIN.voltage_mV", 20000);
  Advance(1ms);
  EXPECT_EQ(Read(0x6113, 1), 22000);
  Advance(1ms);
  EXPECT_EQ(Read(0x6113, 1), 21000);
  Advance(1ms);
  EXPECT_EQ(Read(0x6113, 1), 20500);
}

// Table 4: repeating average, "At every Nth read, the sum is divided by N" with N = 2101h; the
// value holds in between. The default (2, N = 200) "averages the input voltage measurements every
// 200ms".
TEST_F(PsModelTest, InputFilterRepeatingAverage) {
  Write(0x2101, 1, 10, 2);
  Advance(20ms);
  SetNumber("VIN.voltage_mV", 20000);
  Advance(9ms);
  EXPECT_EQ(Read(0x6113, 1), 24000);
  Advance(1ms);
  EXPECT_EQ(Read(0x6113, 1), 20000);
}

TEST_F(PsModelTest, DefaultInputFilterAveragesEvery200ms) {
  Advance(400ms);
  SetNumber("VIN.voltage_mV", 12000);
  Advance(199ms);
  EXPECT_EQ(Read(0x6113, 1), 24000);
  Advance(1ms);
  EXPECT_EQ(Read(0x6113, 1), 12000);
}

// Design decision 10: with steady inputs the node schedules nothing (no 1 ms tick, no timer at
// all in pre-operational with the factory settings); a change wakes the loop, which sleeps again
// once the filter has settled.
TEST_F(PsModelTest, AnIdleNodeDoesNotTick) {
  Advance(5ms);
  EXPECT_FALSE(ps().LoopRunning());
  EXPECT_FALSE(scheduler_.NextDeadline().has_value());
  const auto fired = scheduler_.FiredCount();
  Advance(10s);
  EXPECT_EQ(scheduler_.FiredCount(), fired);
  SetNumber("VIN.voltage_mV", 23000);
  Advance(1ms);
  EXPECT_TRUE(ps().LoopRunning());  // the 200-sample repeating average is settling
  Advance(400ms);
  EXPECT_FALSE(ps().LoopRunning());
  EXPECT_EQ(Read(0x6113, 1), 23000);
}

// §2.3.20 6205h.2/.3 bound the set voltage; 6203h.1 is the hardware maximum.
TEST_F(PsModelTest, SetVoltageIsBoundedByMinAndMax) {
  Write(0x6205, 2, 20000, 4);
  OnByCan();
  Advance(1ms);
  EXPECT_DOUBLE_EQ(io().Number("VOUT.voltage_mV"), 20000);
  Write(0x6205, 3, 22000, 4);  // min above max: the max wins
  Advance(1ms);
  EXPECT_DOUBLE_EQ(io().Number("VOUT.voltage_mV"), 20000);
}

}  // namespace
}  // namespace canfleet::devices::test
