// Analog and universal inputs of the data logger (UMAX181001 §1.3, §1.4 Tables 5-12, §3.3.1,
// §3.3.4-3.3.16, §3.4.1-3.4.18, Table 26): field values, filters, span faults, Table 11 automatic
// updates, Table 12 and the other write rules, digital and analog on/off modes, default TPDOs.

#include "node/devices/datalogger_tc_analog/datalogger_objects.hpp"
#include "tests/unit/datalogger/datalogger_fixture.hpp"

namespace canfleet::devices::test {
namespace {

using namespace datalogger;

constexpr std::uint32_t kInvalidValue = 0x06090030;
constexpr std::uint32_t kValueTooHigh = 0x06090031;
constexpr std::uint32_t kValueTooLow = 0x06090032;
constexpr std::uint32_t kDeviceState = 0x08000022;

class AiTest : public DataLoggerTest {
 protected:
  AiTest() { ConfigureTcLimitsAway(); }
  std::int64_t Fv(int input) { return Read(0, kAiFieldValue, static_cast<std::uint8_t>(input), true); }
};

// §3.2.15: TPDO1-3 carry 7100h sub 1-10 every 100 ms in Operational (node 5: 185h, 285h, 385h);
// §1.4/§4: the default 0-5 V inputs read 2.500 V as 2500 [mV].
TEST_F(AiTest, DefaultTpdosCarryTheFieldValues) {
  SetNumber("IN2.voltage_mV", 1234);
  SetNumber("IN10.voltage_mV", 4321);
  Start(0);
  Advance(100ms);
  const auto frames = Frames(0);
  EXPECT_EQ(frames,
            (std::vector<std::string>{"185#C409D204C409C409", "285#C409C409C409C409", "385#C409E110"}));
  // CAN2 is still pre-operational: no PDOs there.
  EXPECT_TRUE(Frames(1).empty());
}

// §1.4 "New measured values are ready every 10 ms": a change shows on the next 10 ms scan.
TEST_F(AiTest, ValuesFollowTheNextScan) {
  SetNumber("IN1.voltage_mV", 3000);
  EXPECT_EQ(Fv(1), 2500);
  Advance(10ms);
  EXPECT_EQ(Fv(1), 3000);
  EXPECT_EQ(Read(0, kAiProcessValue, 1, true), 3000);  // 7121h/7123h = 7120h/7122h: PV = FV
}

// §1.4 Figure 7: PV = S1PV + (FV - S1FV)(S2PV - S1PV)/(S2FV - S1FV) with 7120h-7123h.
TEST_F(AiTest, ProcessValueScaling) {
  Write(0, kAiScaling1Pv, 3, 0, 2);
  Write(0, kAiScaling2Pv, 3, 1000, 2);  // 0.5 V -> 0, 4.5 V -> 1000
  SetNumber("IN3.voltage_mV", 2500);
  Advance(10ms);
  EXPECT_EQ(Read(0, kAiProcessValue, 3, true), 500);
}

// §1.4 Table 9: moving average every 1 ms, V += (In - V) / 61A1h.
TEST_F(AiTest, MovingAverageFilter) {
  Write(0, kAiFilterType, 1, 1, 1);
  Write(0, kAiFilterConstant, 1, 10, 2);
  Advance(500ms);  // settled on 2500
  ASSERT_EQ(Fv(1), 2500);
  SetNumber("IN1.voltage_mV", 4000);
  Advance(10ms);
  // 10 calls: 4000 - 1500 x 0.9^10 = 3477.0
  EXPECT_NEAR(static_cast<double>(Fv(1)), 3477.0, 1.0);
  Advance(200ms);
  EXPECT_EQ(Fv(1), 4000);
}

// §1.4, §3.4.8-3.4.10, Table 26: with 2110h TRUE, FV > 7149h for the 2112h delay raises
// 20ccF001h on both ports; FV <= 7149h - 2111h clears it. Inputs 1-7 take 1029h sub 3.
TEST_F(AiTest, SpanFaultAfterTheReactionDelayOnBothPorts) {
  Write(0, kAiErrorEnable, 1, 1, 1);
  Write(1, 0x1029, 3, 0, 1);  // CAN2: input faults -> pre-operational
  StartBoth();
  SilenceTpdos();
  SetNumber("IN1.voltage_mV", 4900);  // > 4800
  Advance(990ms);
  EXPECT_TRUE(Frames(0, "085#").empty());
  Advance(20ms);
  EXPECT_EQ(Frames(0, "085#"), std::vector<std::string>{Emcy(kNode1, 0xF001, 0x01, 0x01, 0x20)});
  EXPECT_EQ(Frames(1, "086#"), std::vector<std::string>{Emcy(kNode2, 0xF001, 0x01, 0x01, 0x20)});
  EXPECT_EQ(ErrorField(1), std::vector<std::uint32_t>{0x2001F001});
  EXPECT_EQ(stack(0).State(), canopen::NmtState::kOperational);
  EXPECT_EQ(stack(1).State(), canopen::NmtState::kPreOperational);

  SetNumber("IN1.voltage_mV", 4750);  // above 4800 - 100: still out of range
  Advance(20ms);
  EXPECT_TRUE(Frames(0, "085#").empty());
  SetNumber("IN1.voltage_mV", 4700);
  Advance(20ms);
  EXPECT_EQ(Frames(0, "085#"), std::vector<std::string>{EmcyReset(kNode1, 0)});
  EXPECT_TRUE(ErrorField(0).empty());
}

// §1.4: "Both flags cannot be active at once"; the low flag uses 40ccF001h. Input 9 (universal)
// reports but takes no 1029h reaction ("It only applies to the 7 Analog Inputs").
TEST_F(AiTest, LowFaultOnAUniversalInputTakesNoReaction) {
  Write(0, kAiErrorEnable, 9, 1, 1);
  Write(0, kAiErrorDelay, 9, 0, 2);
  Write(0, 0x1029, 3, 2, 1);
  Start(0);
  SetNumber("IN9.voltage_mV", 100);  // < 200
  Advance(10ms);
  EXPECT_EQ(Frames(0, "085#"), std::vector<std::string>{Emcy(kNode1, 0xF001, 0x01, 0x09, 0x40)});
  EXPECT_EQ(stack(0).State(), canopen::NmtState::kOperational);
}

// Table 11 (5550h TRUE): a new sensor type reloads 2102h, 7148h, 7120h, 7122h, 7149h, 2111h;
// a new range too. Current has 0 decimals (Table 10).
TEST_F(AiTest, AutomaticUpdatesFollowTable11) {
  Write(0, kSensorType, 2, kSensorCurrent, 2);
  EXPECT_EQ(Read(0, kAiFvDigits, 2), 0);
  EXPECT_EQ(Read(0, kAiSpanStart, 2, true), 0);
  EXPECT_EQ(Read(0, kAiScaling1Fv, 2, true), 0);
  EXPECT_EQ(Read(0, kAiScaling2Fv, 2, true), 20);
  EXPECT_EQ(Read(0, kAiSpanEnd, 2, true), 21);
  EXPECT_EQ(Read(0, kAiErrorHysteresis, 2, true), 1);
  Write(1, kAiRange, 2, 1, 1);  // 4-20 mA, written on CAN2: the same shared objects
  EXPECT_EQ(Read(0, kAiSpanStart, 2, true), 3);
  EXPECT_EQ(Read(0, kAiScaling1Fv, 2, true), 4);
  SetNumber("IN2.current_mA", 12);
  Advance(10ms);
  EXPECT_EQ(Fv(2), 12);
  // Writing the type that is already there (a DCF download) changes nothing (README B18).
  Write(0, kAiSpanEnd, 2, 22, 2);
  Write(0, kSensorType, 2, kSensorCurrent, 2);
  EXPECT_EQ(Read(0, kAiRange, 2), 1);
  EXPECT_EQ(Read(0, kAiSpanEnd, 2, true), 22);

  // 5550h FALSE: changing the type changes nothing else (§1.8).
  Write(0, kAutoUpdates, 0, 0, 1);
  Write(0, kSensorType, 3, kSensorCurrent, 2);
  EXPECT_EQ(Read(0, kAiFvDigits, 3), 3);
  EXPECT_EQ(Read(0, kAiScaling2Fv, 3, true), 4500);
}

// Tables 5-7 and §3.4.1-3.4.6: what the device refuses.
TEST_F(AiTest, WriteRules) {
  EXPECT_EQ(TryWrite(0, kAiOperatingMode, 1, kModeDigital, 1),
            SdoAborted(kNode1, kAiOperatingMode, 1, kInvalidValue));
  EXPECT_EQ(TryWrite(0, kAiOperatingMode, 1, 7, 1), SdoAborted(kNode1, kAiOperatingMode, 1, kInvalidValue));
  Write(0, kAiOperatingMode, 8, kModeDigital, 1);
  EXPECT_EQ(TryWrite(0, kSensorType, 1, kSensorFrequency, 2),
            SdoAborted(kNode1, kSensorType, 1, kInvalidValue));
  EXPECT_EQ(TryWrite(0, kSensorType, 10, kSensorPwm, 2), SdoAborted(kNode1, kSensorType, 10, kInvalidValue));
  Write(0, kSensorType, 9, kSensorPwm, 2);
  EXPECT_EQ(TryWrite(0, kAiRange, 9, 1, 1), SdoAborted(kNode1, kAiRange, 9, kValueTooHigh));
  EXPECT_EQ(TryWrite(0, kAiRange, 10, 1, 1),
            SdoAborted(kNode1, kAiRange, 10, kValueTooHigh));  // 0-10 V: 1-7 only
  Write(0, kAiRange, 7, 1, 1);
  // 2102h: read-only while 5550h is TRUE.
  EXPECT_EQ(TryWrite(0, kAiFvDigits, 1, 2, 1), SdoAborted(kNode1, kAiFvDigits, 1, kDeviceState));
  Write(0, kAutoUpdates, 0, 0, 1);
  Write(0, kAiFvDigits, 1, 2, 1);
  // 2010h/2020h sub 1-7 "will not be allowed to change".
  EXPECT_EQ(TryWrite(1, kDiPolarity, 3, 1, 1), SdoAborted(kNode2, kDiPolarity, 3, kInvalidValue));
  Write(1, kDiPolarity, 8, 1, 1);
}

// Table 12: 7148h <= 7120h <= 7122h <= MAX, 7149h <= 110 % MAX, 2111h <= 10 % MAX (0-5 V: MAX
// 5000 mV); 4-20 mA: 7120h >= 4 mA.
TEST_F(AiTest, Table12Limits) {
  EXPECT_EQ(TryWrite(0, kAiScaling2Fv, 1, 5001, 2), SdoAborted(kNode1, kAiScaling2Fv, 1, kValueTooHigh));
  Write(0, kAiScaling2Fv, 1, 5000, 2);
  EXPECT_EQ(TryWrite(0, kAiSpanEnd, 1, 4999, 2), SdoAborted(kNode1, kAiSpanEnd, 1, kValueTooLow));
  Write(0, kAiSpanEnd, 1, 5500, 2);
  EXPECT_EQ(TryWrite(0, kAiSpanEnd, 1, 5501, 2), SdoAborted(kNode1, kAiSpanEnd, 1, kValueTooHigh));
  EXPECT_EQ(TryWrite(0, kAiErrorHysteresis, 1, 501, 2),
            SdoAborted(kNode1, kAiErrorHysteresis, 1, kValueTooHigh));
  EXPECT_EQ(TryWrite(0, kAiSpanStart, 1, 600, 2), SdoAborted(kNode1, kAiSpanStart, 1, kValueTooHigh));
  EXPECT_EQ(TryWrite(0, kAiScaling1Fv, 1, 100, 2), SdoAborted(kNode1, kAiScaling1Fv, 1, kValueTooLow));
  Write(0, kSensorType, 4, kSensorCurrent, 2);
  Write(0, kAiRange, 4, 1, 1);
  Write(0, kAiSpanStart, 4, 0, 2);
  EXPECT_EQ(TryWrite(0, kAiScaling1Fv, 4, 3, 2), SdoAborted(kNode1, kAiScaling1Fv, 4, kValueTooLow));
}

// §1.3 Tables 2 and 4: inputs 8-10 as digital inputs. Open reads LOW without the pull-up and HIGH
// with it; 2010h: 0 normal, 1 inverse, 2 latched (each LOW->HIGH toggles). 6020h and 7100h carry
// the state (Table 10 "Digital Input 0 [On/Off]").
TEST_F(AiTest, DigitalInputModes) {
  Write(0, kAiOperatingMode, 8, kModeDigital, 1);
  EXPECT_EQ(Read(0, kAiScaling2Fv, 8, true), 1);  // Table 11 "Digital Input ... ON"
  Advance(10ms);
  EXPECT_EQ(Read(0, kDiState, 8), 0);
  Write(0, kDiPullup, 8, 1, 1);
  Advance(10ms);
  EXPECT_EQ(Read(0, kDiState, 8), 1);
  EXPECT_EQ(Fv(8), 1);
  Write(0, kDiPolarity, 8, 1, 1);  // inverse
  Advance(10ms);
  EXPECT_EQ(Read(0, kDiState, 8), 0);
  SetEnum("IN8.level", "low");
  Advance(10ms);
  EXPECT_EQ(Read(0, kDiState, 8), 1);

  Write(0, kDiPolarity, 8, 2, 1);  // latched
  Advance(10ms);
  EXPECT_EQ(Read(0, kDiState, 8), 0);
  SetEnum("IN8.level", "high");
  Advance(10ms);
  EXPECT_EQ(Read(0, kDiState, 8), 1);
  SetEnum("IN8.level", "low");  // HIGH -> LOW: no change
  Advance(10ms);
  EXPECT_EQ(Read(0, kDiState, 8), 1);
  SetEnum("IN8.level", "high");
  Advance(10ms);
  EXPECT_EQ(Read(0, kDiState, 8), 0);
  // Other modes: 6020h is 0 (§1.3 "For all other operating modes, object 6020h will always be
  // zero").
  EXPECT_EQ(Read(0, kDiState, 9), 0);
}

// §1.3 Figure 5 (damaged): analog on/off (any input) turns ON at 7122h and OFF at 7120h.
TEST_F(AiTest, AnalogOnOffHysteresis) {
  Write(0, kAiOperatingMode, 2, kModeAnalogOnOff, 1);
  SetNumber("IN2.voltage_mV", 4600);
  Advance(10ms);
  EXPECT_EQ(Read(0, kDiState, 2), 1);
  SetNumber("IN2.voltage_mV", 2000);  // between MIN 500 and MAX 4500: holds
  Advance(10ms);
  EXPECT_EQ(Read(0, kDiState, 2), 1);
  EXPECT_EQ(Fv(2), 2000);  // the analog chain still runs
  SetNumber("IN2.voltage_mV", 400);
  Advance(10ms);
  EXPECT_EQ(Read(0, kDiState, 2), 0);
}

// §1.4 Table 6 and §3.4.5: frequency on input 8, RPM with pulses per revolution (Table 11 RPM
// row, 0.1 rpm); PWM on input 9 in 0.1 %.
TEST_F(AiTest, FrequencyRpmAndPwm) {
  Write(0, kSensorType, 8, kSensorFrequency, 2);
  SetNumber("IN8.frequency_Hz", 1500);
  Advance(10ms);
  EXPECT_EQ(Fv(8), 1500);
  Write(0, kAiPulsesPerRev, 8, 60, 2);
  EXPECT_EQ(Read(0, kAiFvDigits, 8), 1);
  EXPECT_EQ(Read(0, kAiScaling2Fv, 8, true), 30000);
  Advance(10ms);
  EXPECT_EQ(Fv(8), 15000);  // 1500 Hz x 60 / 60 = 1500.0 rpm
  Write(0, kSensorType, 9, kSensorPwm, 2);
  SetNumber("IN9.duty_pct", 42.5);
  Advance(10ms);
  EXPECT_EQ(Fv(9), 425);
}

// §1.4 Table 5: a channel switched off reads 0.
TEST_F(AiTest, ChannelOff) {
  Write(0, kAiOperatingMode, 5, kModeOff, 1);
  Advance(10ms);
  EXPECT_EQ(Fv(5), 0);
  EXPECT_EQ(Read(0, kAiProcessValue, 5, true), 0);
}

}  // namespace
}  // namespace canfleet::devices::test
