// The Quad's analog/pulse input block (AX020506 §2.3, §2.4, §3.3) on a running node: field values
// by sensor type, 10 ms sampling, frequency windows, scaling, autozero, filters, invalid values.
#include "tests/unit/devices/quad_fixture.hpp"

namespace canfleet::devices::test {
namespace {

class QuadAiTest : public QuadTest {};

// §3.1.1 default TPDOs, §3.3.12 field values: with the node operational, the simulated inputs
// appear in TPDO1 (AIN1-4 in mV) and TPDO2 (FIN1-2 duty × 100) at the 100 ms event timer.
TEST_F(QuadAiTest, TpdosCarryTheFieldValuesOfTheSimulatedInputs) {
  Start();
  SetNumber("IN1.voltage_mV", 1000);
  SetNumber("IN2.voltage_mV", 2000);
  SetNumber("IN3.voltage_mV", 3000);
  SetNumber("IN4.voltage_mV", 4000);
  SetNumber("IN5.duty_pct", 12.34);
  SetNumber("IN6.duty_pct", 99.99);
  Advance(99ms);  // t = 100 ms since the NMT start
  EXPECT_EQ(Frames(), (std::vector<std::string>{"185#E803D007B80BA00F", "285#D2040F27", "385#0000",
                                                "485#0000000000000000"}));
  Advance(100ms);
  EXPECT_EQ(Frames("185#"), std::vector<std::string>{"185#E803D007B80BA00F"});
}

// §2.3 "Analog inputs are sampled every 10ms": a change shows at the next sample, not before.
TEST_F(QuadAiTest, InputsAreSampledEveryTenMilliseconds) {
  Advance(10ms);  // t = 10 ms: sampled 2500 mV
  EXPECT_EQ(Read(0x7100, 1), 2500);
  Advance(1ms);
  SetNumber("IN1.voltage_mV", 1234);
  Advance(8ms);  // t = 19 ms
  EXPECT_EQ(Read(0x7100, 1), 2500);
  Advance(1ms);  // t = 20 ms
  EXPECT_EQ(Read(0x7100, 1), 1234);
  EXPECT_EQ(Read(0x7130, 1), 1234);  // default scaling (all 0) leaves PV = FV
}

// §3.3.13: 40 = 0-5000 mV, 42 = 0-10000 mV, 51/52 = current in µA; readings beyond the range
// read full scale.
TEST_F(QuadAiTest, SensorTypesSelectQuantityUnitAndRange) {
  SetNumber("IN1.voltage_mV", 7000);
  SetNumber("IN2.voltage_mV", 7000);
  SetNumber("IN3.current_mA", 12.345);
  SetNumber("IN4.current_mA", 25);
  Write(0x6110, 2, 42, 2);
  Write(0x6110, 3, 51, 2);
  Write(0x6110, 4, 52, 2);
  Advance(10ms);
  EXPECT_EQ(Read(0x7100, 1), 5000);
  EXPECT_EQ(Read(0x7100, 2), 7000);
  EXPECT_EQ(Read(0x7100, 3), 12345);
  EXPECT_EQ(Read(0x7100, 4), 20000);
}

// §2.4, §3.3.9: PWM duty as % × 100; frequency counted over the 2090h window and held until the
// next window ends; a short window has a coarse resolution.
TEST_F(QuadAiTest, PulseInputsMeasureDutyAndFrequencyOverTheWindow) {
  SetNumber("IN5.duty_pct", 37.5);
  Write(0x6110, 6, 60, 2);
  SetNumber("IN6.frequency_Hz", 1234);
  Advance(10ms);
  EXPECT_EQ(Read(0x7100, 5), 3750);
  EXPECT_EQ(Read(0x7100, 6), 0);  // the first 1000 ms window has not ended
  Advance(1000ms);
  EXPECT_EQ(Read(0x7100, 6), 1234);
  Write(0x2090, 2, 100, 2);  // 100 ms window: 123 pulses → 1230 Hz
  Advance(200ms);
  EXPECT_EQ(Read(0x7100, 6), 1230);
}

// §2.3 / DS-404 scaling: PV = PV1 + (FV − FV1)(PV2 − PV1)/(FV2 − FV1) + offset 7124h.
TEST_F(QuadAiTest, ScalingAndOffsetMakeTheProcessValue) {
  SetNumber("IN1.voltage_mV", 2500);
  Write(0x7120, 1, 500, 2);   // FV1 0.5 V
  Write(0x7121, 1, 0, 2);     // PV1 0 bar
  Write(0x7122, 1, 4500, 2);  // FV2 4.5 V
  Write(0x7123, 1, 250, 2);   // PV2 25.0 bar (6132h = 1)
  Write(0x6132, 1, 1, 1);
  Advance(10ms);
  EXPECT_EQ(Read(0x7130, 1, true), 125);
  Write(0x7124, 1, static_cast<std::uint16_t>(-25), 2);
  Advance(10ms);
  EXPECT_EQ(Read(0x7130, 1, true), 100);
  EXPECT_EQ(Read(0x7100, 1), 2500);  // the field value is the measurement
}

// §3.3.20: "zero" to 6125h sets 7124h so that 7130h becomes 0; any other value is refused.
TEST_F(QuadAiTest, AutozeroMakesTheProcessValueZero) {
  SetNumber("IN2.voltage_mV", 1800);
  Advance(10ms);
  EXPECT_EQ(TryWrite(0x6125, 2, 0x12345678, 4), SdoAborted(0x6125, 2, 0x06090030));
  Write(0x6125, 2, 0x6F72657A, 4);
  EXPECT_EQ(Read(0x7124, 2, true), -1800);
  EXPECT_EQ(Read(0x7130, 2, true), 0);
  SetNumber("IN2.voltage_mV", 2000);
  Advance(10ms);
  EXPECT_EQ(Read(0x7130, 2, true), 200);
  EXPECT_EQ(Sdo(SdoRead(0x6125, 2)), SdoAborted(0x6125, 2, 0x06010001));  // write-only
}

// §3.3.23: moving average V_N = V_{N-1} + (Input − V_{N-1}) / C on the process value; the field
// value stays the measurement.
TEST_F(QuadAiTest, MovingAverageFiltersTheProcessValue) {
  SetNumber("IN1.voltage_mV", 1000);
  Write(0x61A0, 1, 1, 1);
  Write(0x61A1, 1, 4, 1);
  Advance(10ms);
  EXPECT_EQ(Read(0x7130, 1), 1000);  // starts from the first sample
  SetNumber("IN1.voltage_mV", 2000);
  Advance(10ms);
  EXPECT_EQ(Read(0x7100, 1), 2000);
  EXPECT_EQ(Read(0x7130, 1), 1250);  // 1000 + (2000 − 1000) / 4
  Advance(10ms);
  EXPECT_EQ(Read(0x7130, 1), 1438);  // 1250 + 750 / 4 = 1437.5
  Advance(500ms);
  EXPECT_EQ(Read(0x7130, 1), 2000);
}

// §3.3.23: repeating average: the mean of every N samples, written at every N-th sample.
TEST_F(QuadAiTest, RepeatingAverageUpdatesEveryNthSample) {
  Write(0x61A0, 3, 2, 1);
  Write(0x61A1, 3, 3, 1);
  SetNumber("IN3.voltage_mV", 1000);
  Advance(10ms);
  SetNumber("IN3.voltage_mV", 2000);
  Advance(10ms);
  EXPECT_EQ(Read(0x7130, 3), 0);  // no block of 3 yet
  SetNumber("IN3.voltage_mV", 3000);
  Advance(10ms);
  EXPECT_EQ(Read(0x7130, 3), 2000);
  SetNumber("IN3.voltage_mV", 4000);
  Advance(20ms);
  EXPECT_EQ(Read(0x7130, 3), 2000);  // holds until the next third sample
  Advance(10ms);
  EXPECT_EQ(Read(0x7130, 3), 4000);
}

// §3.3.23: "Filters are not available for frequency inputs ... 61A0h is ignored".
TEST_F(QuadAiTest, FrequencyInputsAreNotFiltered) {
  Write(0x6110, 5, 60, 2);
  Write(0x2090, 1, 10, 2);
  Write(0x61A0, 5, 1, 1);
  Write(0x61A1, 5, 100, 1);
  SetNumber("IN5.frequency_Hz", 5000);
  Advance(20ms);
  EXPECT_EQ(Read(0x7130, 5), 5000);
}

// §3.3.14: 0 disables the channel.
TEST_F(QuadAiTest, DisabledInputReadsZero) {
  Write(0x6112, 4, 0, 1);
  Advance(10ms);
  EXPECT_EQ(Read(0x7100, 4), 0);
  EXPECT_EQ(Read(0x7130, 4), 0);
}

// Appendix A, Table 1.0 "Disable Inputs": "When disable is selected, no CAN messages associated
// with that channel are sent to the network"; §3.3.14 mode 0 = "Channel not used". A disabled
// input is never checked (no EMCY however far out of range it is) and causes no PDO event; the
// manual gives it no value, so in a TPDO shared with enabled channels its bytes read 0 (README
// choice 16). Enabled again, the same input is checked and reported at once.
TEST_F(QuadAiTest, ADisabledInputSendsNothingOfItsOwn) {
  Write(0x6112, 2, 0, 1);     // AIN2 disabled
  Write(0x20B0, 2, 0, 2);     // no error delay
  Write(0x20A0, 1, 0x02, 1);  // error checking on AIN2
  Start();
  SetNumber("IN1.voltage_mV", 1000);
  SetNumber("IN2.voltage_mV", 4900);  // above 2080h (4800): an error, were it checked
  SetNumber("IN3.voltage_mV", 3000);
  SetNumber("IN4.voltage_mV", 4000);
  Advance(99ms);  // t = 100 ms: the event timers
  std::vector<std::string> tpdo1, emcy;
  for (const auto& f : Frames()) {
    if (f.starts_with("185#")) tpdo1.push_back(f);
    if (f.starts_with("085#")) emcy.push_back(f);
  }
  EXPECT_EQ(tpdo1, std::vector<std::string>{"185#E8030000B80BA00F"});
  EXPECT_TRUE(emcy.empty()) << ::testing::PrintToString(emcy);
  EXPECT_EQ(Read(0x1003, 0), 0);
  EXPECT_EQ(Read(0x6000, 1), 0);  // §3.2: not a digital input either

  Write(0x6112, 2, 1, 1);  // normal operation again
  Advance(10ms);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{Emcy(0xFF01, 0x01, 2, 0x01)});
}

// Appendix A, Table 1.0: a TPDO that carries only disabled channels (TPDO1 maps 7100h.1-4) is
// not sent at all; enabling one channel brings it back on its event timer (README choice 16).
TEST_F(QuadAiTest, ATpdoOfOnlyDisabledInputsIsNotSent) {
  for (std::uint8_t n = 1; n <= 4; ++n)
    Write(0x6112, n, 0, 1);
  Start();
  Advance(299ms);
  EXPECT_TRUE(Frames("185#").empty());
  Write(0x6112, 3, 1, 1);  // AIN3 in use again
  SetNumber("IN3.voltage_mV", 3000);
  Advance(200ms);
  EXPECT_FALSE(Frames("185#").empty());
}

// §3.3.13, §3.3.14: a value not listed → SDO abort, previous value unchanged.
TEST_F(QuadAiTest, InvalidSensorTypeOrModeIsRefusedAndTheOldValueKept) {
  EXPECT_EQ(TryWrite(0x6110, 1, 41, 2), SdoAborted(0x6110, 1, 0x06090030));
  EXPECT_EQ(TryWrite(0x6110, 1, 60, 2), SdoAborted(0x6110, 1, 0x06090030));  // frequency: FIN only
  EXPECT_EQ(TryWrite(0x6110, 5, 40, 2), SdoAborted(0x6110, 5, 0x06090030));  // voltage: AIN only
  EXPECT_EQ(TryWrite(0x6112, 2, 5, 1), SdoAborted(0x6112, 2, 0x06090030));
  EXPECT_EQ(Read(0x6110, 1), 40);
  EXPECT_EQ(Read(0x6110, 5), 10000);
  EXPECT_EQ(Read(0x6112, 2), 1);
  Write(0x6110, 1, 52, 2);
  Write(0x6112, 2, 20, 1);
}

// §3.3.1-8 value ranges: each profile point lies between its neighbours, the last below the
// sensor type's full scale (5000 for 0-5 V, 10000 for 0-10 V).
TEST_F(QuadAiTest, ProfilePointsMustStayOrdered) {
  EXPECT_EQ(TryWrite(0x2010, 1, 600, 2), SdoAborted(0x2010, 1, 0x06090031));   // above 2020h = 500
  EXPECT_EQ(TryWrite(0x2070, 1, 1000, 2), SdoAborted(0x2070, 1, 0x06090032));  // below 2060h = 3600
  EXPECT_EQ(TryWrite(0x2080, 1, 6000, 2), SdoAborted(0x2080, 1, 0x06090031));  // 0-5 V: max 5000
  EXPECT_EQ(TryWrite(0x2002, 1, 1000, 2), SdoAborted(0x2002, 1, 0x06090032));  // below 2001h
  Write(0x6110, 1, 42, 2);
  Write(0x2080, 1, 9000, 2);
  Write(0x2070, 1, 8000, 2);
  EXPECT_EQ(Read(0x2080, 1), 9000);
  EXPECT_EQ(TryWrite(0x2090, 1, 5, 2), SdoAborted(0x2090, 1, 0x06090032));  // window 10..10000 ms
}

}  // namespace
}  // namespace canfleet::devices::test
