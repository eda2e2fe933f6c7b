// The analog input block (UMAX020411A §1.3, §3.3.3-3.3.15, §3.4.4-3.4.18): what a master may write
// (Tables 4-6 and 11, with the CiA 301 abort codes), the 5550h auto-update cascade of Table 10, the
// measurement per sensor type, the filters, and the span faults with their delay and hysteresis.
#include "tests/unit/valve/valve_fixture.hpp"

namespace canfleet::devices::valve::test {
namespace {

constexpr std::uint32_t kInvalid = 0x06090030;
constexpr std::uint32_t kTooHigh = 0x06090031;
constexpr std::uint32_t kTooLow = 0x06090032;
constexpr std::uint32_t kDeviceState = 0x08000022;

class ValveInputTest : public ValveTest {
 protected:
  /// 2102h, 7148h, 7120h, 7122h, 7149h, 2111h of input `sub` (Table 10's columns).
  std::vector<std::int64_t> Row(std::uint8_t sub) {
    return {Read(0x2102, sub),       Read(0x7148, sub, true), Read(0x7120, sub, true),
            Read(0x7122, sub, true), Read(0x7149, sub, true), Read(0x2111, sub, true)};
  }
  std::uint32_t Entry(std::uint8_t sub) { return static_cast<std::uint32_t>(Read(0x1003, sub)); }
};

using Values = std::vector<std::int64_t>;

// Table 5 and §1.1: the sensor types a pin has; everything else is refused.
TEST_F(ValveInputTest, SensorTypeAcceptsOnlyWhatThePinMeasures) {
  Refused(0x6110, 1, 30, 2, kTooLow);      // below Table 5 (EDS limit 40)
  Refused(0x6110, 1, 45, 2, kInvalid);     // not a Table 5 value
  Refused(0x6110, 7, 11000, 2, kInvalid);  // UI7 has no resistive input
  Refused(0x6110, 2, 60, 2, kInvalid);     // frequency only on UI1, 3, 5, 7
  Refused(0x6110, 4, 10000, 2, kInvalid);  // PWM likewise
  Refused(0x6110, 8, 40, 2, kInvalid);     // DI1 has no voltage input
  Write(0x6110, 7, 60, 2);
  Write(0x6110, 6, 11000, 2);
  Write(0x6110, 10, 60, 2);  // DI3 frequency
}

// Table 4: 0, 1, 10, 20; "Digital Input 2 and 4 cannot be set to other values" than digital (or off).
TEST_F(ValveInputTest, OperatingModeAcceptsTable4) {
  Refused(0x6112, 1, 5, 1, kInvalid);
  Refused(0x6112, 9, 1, 1, kInvalid);
  Refused(0x6112, 11, 20, 1, kInvalid);
  Refused(0x6112, 1, 21, 1, kTooHigh);
  Write(0x6112, 9, 0, 1);
  Write(0x6112, 8, 1, 1);
  Write(0x6112, 1, 20, 1);
}

// Table 6: voltage and current have ranges 0 and 1, the other types only 0.
TEST_F(ValveInputTest, InputRangeFollowsTheSensorType) {
  Refused(0x2100, 1, 2, 1, kTooHigh);
  Write(0x2100, 1, 1, 1);
  Write(0x6110, 1, 11000, 2);
  Refused(0x2100, 1, 1, 1, kInvalid);
}

// §3.4.6: 2102h is "normally read-only ... When object 5550h is set to FALSE, this object becomes
// writeable".
TEST_F(ValveInputTest, DecimalDigitsWritableOnlyWithoutAutoUpdates) {
  Refused(0x2102, 1, 2, 1, kDeviceState);
  Write(0x5550, 0, 0, 1);
  Write(0x2102, 1, 2, 1);
  EXPECT_EQ(Read(0x2102, 1), 2);
}

// Table 10 through 5550h: each type/range loads its row (and 7121h/7123h/6132h follow for PV = FV).
TEST_F(ValveInputTest, SensorTypeAndRangeLoadTable10) {
  EXPECT_EQ(Row(1), (Values{3, 200, 500, 4500, 4800, 100}));  // factory: 0-5 V
  Write(0x2100, 1, 1, 1);
  EXPECT_EQ(Row(1), (Values{3, 200, 500, 9500, 9800, 200}));  // 0-10 V
  Write(0x6110, 1, 50, 2);
  EXPECT_EQ(Read(0x2100, 1), 0);  // the current type's default range
  EXPECT_EQ(Row(1),
            (Values{0, 0, 0, 20, 21, 1}));  // 0-20 mA (README: the printed 30000/32000/250 break Table 11)
  Write(0x2100, 1, 1, 1);
  EXPECT_EQ(Row(1), (Values{0, 3, 4, 20, 21, 1}));  // 4-20 mA
  EXPECT_EQ(Read(0x7121, 1), 4);
  EXPECT_EQ(Read(0x7123, 1), 20);
  EXPECT_EQ(Read(0x6132, 1), 0);
  Write(0x6110, 1, 11000, 2);
  EXPECT_EQ(Row(1), (Values{2, 2, 10, 20000, 25000, 1}));  // resistive, 0.01 kOhm
  Write(0x6110, 1, 60, 2);
  EXPECT_EQ(Row(1), (Values{0, 100, 150, 30000, 32000, 5}));  // frequency
  Write(0x2101, 1, 2, 2);
  EXPECT_EQ(Row(1), (Values{1, 500, 1000, 30000, 32767, 100}));  // RPM; 33000 held at INTEGER16
  Write(0x6110, 1, 10000, 2);
  EXPECT_EQ(Row(1), (Values{1, 10, 50, 950, 990, 1}));  // PWM, 0.1 %
  Write(0x6112, 1, 10, 1);
  EXPECT_EQ(Row(1), (Values{0, 0, 0, 1, 1, 0}));  // digital
}

// §1.3: with 5550h FALSE "changing an object will have no impact on any other objects".
TEST_F(ValveInputTest, NoCascadeWithoutAutoUpdates) {
  Write(0x5550, 0, 0, 1);
  Write(0x6110, 1, 50, 2);
  EXPECT_EQ(Row(1), (Values{3, 200, 500, 4500, 4800, 100}));
}

// Table 11 for 0-5 V (MAX 5000 mV): 7148h 0..7120h, 7120h 7148h..7122h, 7122h 7120h..min(7149h,
// MAX), 7149h 7122h..110 % MAX, 2111h 0..10 % MAX.
TEST_F(ValveInputTest, Table11RangesForVoltage) {
  Refused(0x7148, 1, 501, 2, kTooHigh);
  Refused(0x7120, 1, 199, 2, kTooLow);
  Refused(0x7120, 1, 4501, 2, kTooHigh);
  Refused(0x7122, 1, 499, 2, kTooLow);
  Refused(0x7122, 1, 4801, 2, kTooHigh);
  Refused(0x7149, 1, 5501, 2, kTooHigh);
  Refused(0x7149, 1, 4499, 2, kTooLow);
  Refused(0x2111, 1, 501, 2, kTooHigh);
  Write(0x7149, 1, 5500, 2);
  Write(0x7122, 1, 5000, 2);
  Refused(0x7122, 1, 5001, 2, kTooHigh);  // above MAX even below 7149h
  Write(0x2111, 1, 500, 2);
  Write(0x7148, 1, 0, 2);
}

// Table 11 floors: 4-20 mA scaling 1 not below 4 mA; resistive not below 20 Ohm (2 x 0.01 kOhm).
TEST_F(ValveInputTest, Table11FloorsForCurrentAndResistance) {
  Write(0x6110, 2, 50, 2);
  Write(0x2100, 2, 1, 1);
  Write(0x7148, 2, 0, 2);
  Refused(0x7120, 2, 3, 2, kTooLow);
  Write(0x7120, 2, 4, 2);
  Refused(0x7149, 2, 23, 2, kTooHigh);  // 110 % of 20 mA = 22
  Write(0x6110, 3, 11000, 2);
  Write(0x7148, 3, 0, 2);
  Refused(0x7120, 3, 1, 2, kTooLow);
  Write(0x7120, 3, 2, 2);
}

// §1.3 / Table 9: each type reads its pin in its unit: mA, 0.01 kOhm, Hz, 0.1 RPM, 0.1 %.
TEST_F(ValveInputTest, MeasuresEachSensorType) {
  Write(0x6110, 2, 50, 2);
  SetNumber("IN2.current_mA", 12.4);
  Write(0x6110, 3, 11000, 2);
  SetNumber("IN3.resistance_ohm", 4700);
  Write(0x6110, 5, 60, 2);
  SetNumber("IN5.frequency_Hz", 1500);
  Write(0x6110, 7, 10000, 2);
  SetNumber("IN7.duty_pct", 37.5);
  Write(0x6110, 1, 60, 2);
  Write(0x2101, 1, 4, 2);
  SetNumber("IN1.frequency_Hz", 200);  // 200 Hz x 60 / 4 = 3000 RPM
  Advance(2ms);
  EXPECT_EQ(Read(0x7100, 2, true), 12);
  EXPECT_EQ(Read(0x7100, 3, true), 470);
  EXPECT_EQ(Read(0x7100, 5, true), 1500);
  EXPECT_EQ(Read(0x7100, 7, true), 375);
  EXPECT_EQ(Read(0x7100, 1, true), 30000);
}

// §1.3: the PV is the line through (7120h, 7121h) and (7122h, 7123h), "Figure 7".
TEST_F(ValveInputTest, ProcessValueScaling) {
  Write(0x7121, 1, 0, 2);
  Write(0x7123, 1, 1000, 2);  // 0.5..4.5 V -> 0..1000
  SetNumber("IN1.voltage_mV", 2500);
  Advance(2ms);
  EXPECT_EQ(Read(0x7130, 1, true), 500);
}

// §1.3 Table 8, 1: V[n] = V[n-1] + (In - V[n-1]) / 61A1h, called every 1 ms.
TEST_F(ValveInputTest, MovingAverageFilter) {
  Write(0x61A0, 1, 1, 1);
  Advance(2ms);
  SetNumber("IN1.voltage_mV", 3500);
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), 2600);
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), 2690);
  Advance(500ms);
  EXPECT_EQ(Read(0x7100, 1, true), 3500);
  EXPECT_TRUE(valve().Idle());
}

// §1.3 Table 8, 2: the sum of 61A1h readings divided by 61A1h, then held until the next block.
TEST_F(ValveInputTest, RepeatingAverageFilter) {
  Write(0x61A0, 1, 2, 1);
  Advance(20ms);
  SetNumber("IN1.voltage_mV", 3500);
  Advance(9ms);
  const auto before = Read(0x7100, 1, true);
  EXPECT_TRUE(before == 2500 || (before > 2500 && before < 3500)) << before;
  Advance(20ms);
  EXPECT_EQ(Read(0x7100, 1, true), 3500);
}

// §1.3 Table 8, 3, §3.4.11-3.4.18: the default second-order low pass (N0-N2 120/241/120, O1/O2
// 704/-164, >> 10) called every 61A1h = 10 ms; its DC gain 481/484 leaves a settled FV 0.6 % low.
TEST_F(ValveInputTest, ThirdOrderFilterDefaultCoefficients) {
  SetNumber("IN1.voltage_mV", 3500);
  Advance(2ms);
  Write(0x2110, 1, 0, 1);  // the filter starts from 0: keep the span check out of it
  Write(0x61A0, 1, 3, 1);
  Advance(3s);
  const auto fv = Read(0x7100, 1, true);
  EXPECT_GE(fv, 3470);
  EXPECT_LE(fv, 3482);
  EXPECT_LT(fv, 3500);
}

// §1.3: below 7148h for 2112h -> 4001F001h, EMCY F001h; the flag clears only at 7148h + 2111h.
TEST_F(ValveInputTest, SpanLowFaultWithDelayAndHysteresis) {
  SetNumber("IN1.voltage_mV", 100);
  Advance(1000ms);
  EXPECT_TRUE(Frames("085#").empty());
  Advance(1ms);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{Emcy(0xF001, 0x01, 1, 0x40)});
  EXPECT_EQ(Read(0x1003, 0), 1);
  EXPECT_EQ(Entry(1), 0x4001F001u);
  EXPECT_EQ(Read(0x1001, 0), 1);
  SetNumber("IN1.voltage_mV", 250);  // back above 7148h but below 7148h + 2111h = 300
  Advance(10ms);
  EXPECT_TRUE(Frames("085#").empty());
  EXPECT_EQ(Read(0x1003, 0), 1);
  SetNumber("IN1.voltage_mV", 300);
  Advance(2ms);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{EmcyReset()});
  EXPECT_EQ(Read(0x1003, 0), 0);
  EXPECT_EQ(Read(0x1001, 0), 0);
}

// §1.3: above 7149h -> 20nnF001h; it clears at 7149h - 2111h.
TEST_F(ValveInputTest, SpanHighFault) {
  Write(0x2112, 3, 200, 2);
  SetNumber("IN3.voltage_mV", 4900);
  Advance(201ms);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{Emcy(0xF001, 0x01, 3, 0x20)});
  EXPECT_EQ(Entry(1), 0x2003F001u);
  SetNumber("IN3.voltage_mV", 4750);  // inside the span, not yet 7149h - 2111h = 4700
  Advance(10ms);
  EXPECT_EQ(Read(0x1003, 0), 1);
  SetNumber("IN3.voltage_mV", 4700);
  Advance(2ms);
  EXPECT_EQ(Read(0x1003, 0), 0);
}

// §3.4.10: a flag that goes away during 2112h is never reported.
TEST_F(ValveInputTest, SpanFlagShorterThanTheDelayIsNotReported) {
  SetNumber("IN2.voltage_mV", 50);
  Advance(600ms);
  SetNumber("IN2.voltage_mV", 2500);
  Advance(2s);
  EXPECT_TRUE(Frames("085#").empty());
}

// §1.3: "Both flags cannot be active at once. Setting either one of these flags automatically
// clears the other."
TEST_F(ValveInputTest, LowFlagReplacedByHighFlag) {
  Write(0x2112, 1, 0, 2);
  SetNumber("IN1.voltage_mV", 100);
  Advance(2ms);
  SetNumber("IN1.voltage_mV", 5000);
  Advance(2ms);
  EXPECT_EQ(Frames("085#"), (std::vector<std::string>{Emcy(0xF001, 0x01, 1, 0x40), EmcyReset(),
                                                      Emcy(0xF001, 0x01, 1, 0x20)}));
  EXPECT_EQ(Read(0x1003, 0), 1);
  EXPECT_EQ(Entry(1), 0x2001F001u);
}

// §3.4.8: with 2110h FALSE nothing is reported.
TEST_F(ValveInputTest, ErrorDetectionDisabled) {
  Write(0x2110, 1, 0, 1);
  SetNumber("IN1.voltage_mV", 0);
  Advance(3s);
  EXPECT_TRUE(Frames("085#").empty());
}

// §1.3, §3.2.13: an input fault applies 1029h sub 3 (2 = stopped).
TEST_F(ValveInputTest, InputFaultAppliesErrorBehaviourSub3) {
  Write(0x1029, 3, 2, 1);
  Start();
  Write(0x2112, 4, 0, 2);
  SetNumber("IN4.voltage_mV", 0);
  Advance(2ms);
  EXPECT_EQ(stack().State(), canopen::NmtState::kStopped);
}

// §1.3, §3.2.4: the EMCY list covers UI1-UI7 only; a DI1 set to PWM and out of span reports nothing.
TEST_F(ValveInputTest, DigitalInputsHaveNoEmcy) {
  Write(0x6112, 8, 1, 1);  // DI1 as PWM (6110h 10000): Table 10 PWM row, span 10..990 (0.1 %)
  Write(0x2112, 8, 0, 2);
  SetNumber("IN8.duty_pct", 0);
  Advance(10ms);
  EXPECT_TRUE(Frames("085#").empty());
}

// §1.2 Figure 5 (lost; README): mode 20 drives 6020h from the FV: ON at 7122h, OFF at 7120h.
TEST_F(ValveInputTest, AnalogOnOffMode) {
  Write(0x6112, 1, 20, 1);
  Advance(2ms);
  EXPECT_EQ(Read(0x6020, 1), 0);
  EXPECT_EQ(Read(0x7100, 1, true), 2500);
  SetNumber("IN1.voltage_mV", 4500);
  Advance(2ms);
  EXPECT_EQ(Read(0x6020, 1), 1);
  SetNumber("IN1.voltage_mV", 2000);
  Advance(2ms);
  EXPECT_EQ(Read(0x6020, 1), 1);  // held between the thresholds
  SetNumber("IN1.voltage_mV", 500);
  Advance(2ms);
  EXPECT_EQ(Read(0x6020, 1), 0);
}

// §1.2: "For all other operating modes, object 6020h will always be zero."
TEST_F(ValveInputTest, NormalModeLeavesReadStateZero) {
  SetEnum("IN1.level", "high");
  Advance(2ms);
  EXPECT_EQ(Read(0x6020, 1), 0);
}

}  // namespace
}  // namespace canfleet::devices::valve::test
