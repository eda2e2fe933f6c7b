// The inputs of the AX023241 used separately (1.2.1-1.2.3, Tables 1-5, C3-1.3.1-1.3.16,
// C3-1.4.1-1.4.6): frequency, PWM and digital readings, the objects a type rewrites, the filter,
// out-of-span faults with their EMCY/1003h/1029h, and change-of-state TPDOs of 6000h.
#include "tests/unit/encoder/encoder_fixture.hpp"

namespace canfleet::devices::encoder::test {
namespace {

class InputTest : public EncoderTest {
 protected:
  void MakeFrequencyInput1() {
    Write(0x6110, 1, 60, 2);
    Advance(1ms);
  }
};

// Table 1 / Table 3: 6110h = 60 is a frequency input; writing it sets 2100h to 0 (0.5-50 Hz) and
// rewrites 2102h, 7120h-7123h, 7148h/7149h (input_defaults.hpp). Below 0.5 Hz no edge is measured.
TEST_F(InputTest, FrequencyInputInItsThreeRanges) {
  Write(0x2100, 1, 2, 1);
  MakeFrequencyInput1();
  EXPECT_EQ(Read(0x2100, 1), 0);
  EXPECT_EQ(Read(0x2102, 1), 2);
  EXPECT_EQ(Read(0x7120, 1, true), 50);
  EXPECT_EQ(Read(0x7122, 1, true), 5000);
  EXPECT_EQ(Read(0x7148, 1, true), 40);
  EXPECT_EQ(Read(0x7149, 1, true), 5250);
  EXPECT_EQ(Read(0x7100, 1, true), 2500);  // IN1.frequency_Hz default 25 Hz, 2 decimals
  EXPECT_EQ(Read(0x7130, 1, true), 2500);
  SetNumber("IN1.frequency_Hz", 0.4);
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), 0);
  Write(0x2100, 1, 2, 1);  // 100 Hz - 10 kHz, whole Hz
  SetNumber("IN1.frequency_Hz", 5000);
  Advance(1ms);
  EXPECT_EQ(Read(0x2102, 1), 0);
  EXPECT_EQ(Read(0x7100, 1, true), 5000);
  SetNumber("IN1.frequency_Hz", 50);
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), 0);
}

// Table 1: "no values other than what are shown here will be accepted"; Table 3: PWM has ranges
// 0 (< 1 kHz) and 1 (> 100 Hz) only.
TEST_F(InputTest, SensorTypeAndRangeAreChecked) {
  EXPECT_EQ(TryWrite(0x6110, 1, 40, 2), SdoAborted(0x6110, 1, 0x06090032));  // below the table's 60
  EXPECT_EQ(TryWrite(0x6110, 1, 10001, 2), SdoAborted(0x6110, 1, 0x06090030));
  EXPECT_EQ(TryWrite(0x6112, 1, 5, 1), SdoAborted(0x6112, 1, 0x06090030));
  Write(0x6110, 1, 10000, 2);
  EXPECT_EQ(TryWrite(0x2100, 1, 2, 1), SdoAborted(0x2100, 1, 0x06090031));
  Write(0x2100, 1, 1, 1);
}

// Table 3 PWM: the duty cycle in 0.1 % (2102h = 1), measured inside the range's frequency band.
TEST_F(InputTest, PwmInputMeasuresDutyInsideItsBand) {
  Write(0x6110, 1, 10000, 2);
  SetNumber("IN1.frequency_Hz", 500);
  SetNumber("IN1.duty_pct", 40);
  Advance(1ms);
  EXPECT_EQ(Read(0x2102, 1), 1);
  EXPECT_EQ(Read(0x7100, 1, true), 400);
  Write(0x2100, 1, 1, 1);  // high frequency: > 100 Hz
  SetNumber("IN1.frequency_Hz", 50);
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), 0);
  SetNumber("IN1.frequency_Hz", 5000);
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), 400);
}

// Table 2 (6112h = 10), Table 3 "Digital", Table 4, 1.2.2: normal, inverse ("active low" with the
// 1 kOhm pull-up), latched (push-button); 6000h bit per input, XOR 6002h.
TEST_F(InputTest, DigitalInputResponsesAndPulls) {
  MakeFrequencyInput1();
  Write(0x6112, 1, 10, 1);
  SetEnum("IN1.level", "high");
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), 1);
  EXPECT_EQ(Read(0x6000, 1), 0x01);
  SetEnum("IN1.level", "open");
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), 0);  // floating, no pull resistor
  Write(0x2020, 1, 1, 1);               // 1 kOhm pull-up
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), 1);
  Write(0x2100, 1, 1, 1);  // inverse: the floating pull-up reads OFF, grounded reads ON
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), 0);
  SetEnum("IN1.level", "low");
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), 1);
  Write(0x6002, 1, 0x01, 1);
  Advance(1ms);
  EXPECT_EQ(Read(0x6000, 1), 0x00);
  Write(0x6002, 1, 0x00, 1);
  Write(0x2100, 1, 2, 1);  // latched: every OFF->ON toggles
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), 0);
  SetEnum("IN1.level", "high");
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), 1);
  SetEnum("IN1.level", "low");
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), 1);
  SetEnum("IN1.level", "high");
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), 0);
}

// C3-1.3.1: 6000h is PDO-mappable: a TPDO mapping it goes out when a digital input changes.
TEST_F(InputTest, DigitalStateChangeSendsAnEventTpdo) {
  MakeFrequencyInput1();
  Write(0x6112, 1, 10, 1);
  Write(0x1A01, 0, 0, 1);
  Write(0x1A01, 1, 0x60000108, 4);
  Write(0x1A01, 0, 1, 1);
  Write(0x1801, 1, 0x40000285, 4);
  SilenceTpdo1();
  Start();
  Advance(10ms);
  Frames();
  SetEnum("IN1.level", "high");
  Advance(1ms);
  EXPECT_EQ(Frames("285#"), std::vector<std::string>{"285#01"});
}

// C3-1.4.3-1.4.5 (algorithm of the family, span_monitor.hpp): below 7148h for 2112h ms -> EMCY
// F001h, 1003h 40nnF001h; back above 7148h + 2111h -> error reset. The device sleeps through the
// delay (one evaluation at its end, design decision 10).
TEST_F(InputTest, BelowSpanStartBecomesAFaultAfterTheDelay) {
  MakeFrequencyInput1();
  Write(0x2112, 1, 500, 2);
  Write(0x2110, 1, 1, 1);
  SetNumber("IN1.frequency_Hz", 0.2);
  Advance(1ms);
  const auto evaluations = device().Evaluations();
  Advance(499ms);
  EXPECT_TRUE(Frames("085#").empty());
  EXPECT_LE(device().Evaluations() - evaluations, 1u);
  Advance(1ms);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{Emcy(0xF001, 1, 0x40)});
  EXPECT_EQ(Read(0x1003, 0), 1);
  EXPECT_EQ(Read(0x1003, 1), 0x4001F001);
  EXPECT_EQ(Read(0x1001, 0), 1);
  SetNumber("IN1.frequency_Hz", 0.8);  // 80 < 40 + 50: still low
  Advance(10ms);
  EXPECT_TRUE(Frames("085#").empty());
  SetNumber("IN1.frequency_Hz", 25);
  Advance(1ms);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{"085#0000000000000000"});
  EXPECT_EQ(Read(0x1003, 0), 0);
  EXPECT_EQ(Read(0x1001, 0), 0);
}

// Above 7149h -> 20nnF001h; an input fault applies 1029h sub 3 (2 = stopped).
TEST_F(InputTest, AboveSpanEndWithZeroDelayStopsTheNodeBy1029h) {
  MakeFrequencyInput1();
  Write(0x1029, 3, 2, 1);
  Write(0x2112, 1, 0, 2);
  Write(0x2110, 1, 1, 1);
  Start();
  SetNumber("IN1.frequency_Hz", 60);
  Advance(1ms);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{Emcy(0xF001, 1, 0x20)});
  EXPECT_EQ(stack().State(), canopen::NmtState::kStopped);
  EXPECT_EQ(od().GetUnsigned(0x1003, 1), 0x2001F001u);  // no SDO in stopped
}

// 1.2.3 Equation 1: V_N = V_(N-1) + (Input - V_(N-1)) / C, one call per ms; the device ticks until
// the filter has settled, then sleeps.
TEST_F(InputTest, MovingAverageFilterSettlesThenSleeps) {
  MakeFrequencyInput1();
  Write(0x61A1, 1, 4, 2);
  Write(0x61A0, 1, 1, 1);
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), 2500);
  SetNumber("IN1.frequency_Hz", 50);
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), 3125);
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), 3594);
  EXPECT_TRUE(device().Ticking());
  Advance(200ms);
  EXPECT_EQ(Read(0x7100, 1, true), 5000);
  EXPECT_FALSE(device().Ticking());
}

// 1.2.3 Equation 2: the average of C readings, held until the next C are in.
TEST_F(InputTest, RepeatingAverageFilterHoldsBetweenAverages) {
  MakeFrequencyInput1();
  Write(0x61A1, 1, 10, 2);
  Write(0x61A0, 1, 2, 1);
  Advance(20ms);
  SetNumber("IN1.frequency_Hz", 50);
  Advance(9ms);
  EXPECT_EQ(Read(0x7100, 1, true), 2500);  // nine readings in: the previous average holds
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), 5000);
  EXPECT_FALSE(device().Ticking());
}

}  // namespace
}  // namespace canfleet::devices::encoder::test
