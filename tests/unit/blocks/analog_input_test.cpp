// Analog input chain, span faults and the auto-update table: valve UMAX020411A §1.3 (Tables 9-11,
// fault text after Table 11), logger UMAX181001 §1.4 (Tables 10-11).
#include <gtest/gtest.h>

#include <chrono>

#include "node/devices/blocks/analog_input.hpp"
#include "node/devices/blocks/analog_input_defaults.hpp"
#include "node/devices/blocks/span_monitor.hpp"

namespace canfleet::devices::blocks::test {
namespace {

using namespace std::chrono_literals;

// 0-5 V defaults (Table 10): span 200..4800 mV, hysteresis 100 mV, delay 1000 ms (2112h).
const SpanParams kSpan{};

// "When (7100h < 7148h), an 'Out of Range Low' flag is set. If the flag stays active for the 2112h
// AI Error Reaction Delay time, an ... EMCY message will be added".
TEST(SpanMonitorTest, LowFlagBecomesAFaultAfterTheDelay) {
  SpanMonitor m;
  m.Update(kSpan, 100, 0ms);
  EXPECT_EQ(m.Flag(), SpanFlag::kLow);
  EXPECT_FALSE(m.Faulted());
  EXPECT_TRUE(m.Busy());
  m.Update(kSpan, 100, 999ms);
  EXPECT_FALSE(m.Faulted());
  m.Update(kSpan, 100, 1ms);
  EXPECT_TRUE(m.Faulted());
  EXPECT_EQ(m.Fault(), SpanFlag::kLow);
  EXPECT_FALSE(m.Busy());
}

// "To clear an 'Out of Range Low' flag, AI Input FV >= (AI Span Start + AI Error Clear
// Hysteresis)"; high: "FV <= (AI Span End - AI Error Clear Hysteresis)".
TEST(SpanMonitorTest, FlagsClearWithHysteresis) {
  SpanMonitor m;
  m.Update(kSpan, 100, 0ms);
  m.Update(kSpan, 100, 1000ms);
  m.Update(kSpan, 250, 10ms);
  EXPECT_TRUE(m.Faulted());
  m.Update(kSpan, 299, 10ms);
  EXPECT_EQ(m.Flag(), SpanFlag::kLow);
  m.Update(kSpan, 300, 10ms);
  EXPECT_EQ(m.Flag(), SpanFlag::kNone);
  EXPECT_FALSE(m.Faulted());

  m.Update(kSpan, 4900, 10ms);
  EXPECT_EQ(m.Flag(), SpanFlag::kHigh);
  m.Update(kSpan, 4750, 10ms);
  EXPECT_EQ(m.Flag(), SpanFlag::kHigh);
  m.Update(kSpan, 4700, 10ms);
  EXPECT_EQ(m.Flag(), SpanFlag::kNone);
}

// A flag that clears before the delay never becomes a fault; a new flag counts from zero.
TEST(SpanMonitorTest, ShortExcursionsDoNotFault) {
  SpanMonitor m;
  m.Update(kSpan, 100, 0ms);
  m.Update(kSpan, 100, 900ms);
  m.Update(kSpan, 400, 10ms);
  EXPECT_EQ(m.Flag(), SpanFlag::kNone);
  m.Update(kSpan, 100, 10ms);
  m.Update(kSpan, 100, 900ms);
  EXPECT_FALSE(m.Faulted());
  EXPECT_EQ(m.Held(), 900ms);
}

// "Both flags cannot be active at once. Setting either one of these flags automatically clears the
// other." A fault of one kind does not carry over to the other.
TEST(SpanMonitorTest, SwitchingFlagsRestartsTheDelay) {
  SpanMonitor m;
  m.Update(kSpan, 100, 0ms);
  m.Update(kSpan, 100, 1000ms);
  ASSERT_EQ(m.Fault(), SpanFlag::kLow);
  m.Update(kSpan, 5000, 10ms);
  EXPECT_EQ(m.Flag(), SpanFlag::kHigh);
  EXPECT_FALSE(m.Faulted());
  m.Update(kSpan, 5000, 1000ms);
  EXPECT_EQ(m.Fault(), SpanFlag::kHigh);
}

// 2110h FALSE: no flags; 2112h = 0: the fault is immediate.
TEST(SpanMonitorTest, DisableAndZeroDelay) {
  SpanMonitor m;
  SpanParams off = kSpan;
  off.enabled = false;
  m.Update(off, 0, 5000ms);
  EXPECT_EQ(m.Flag(), SpanFlag::kNone);
  SpanParams now = kSpan;
  now.delay = 0ms;
  m.Update(now, 0, 0ms);
  EXPECT_TRUE(m.Faulted());
  m.Update(off, 0, 0ms);
  EXPECT_FALSE(m.Faulted());
}

// Digest §8 of the valve: with the default span start 200 mV and 2110h TRUE, an unconnected input
// (0 V) raises "out of range low" 1 s after power-up; as a control source it is then in error
// (Table 17 limits 7120h..7122h, 2102h digits).
TEST(AnalogInputTest, UnconnectedInputFaultsLowAfterOneSecond) {
  AnalogInput ai;
  const AnalogInputParams p;
  ai.Tick(999ms, p, 0.0);
  EXPECT_EQ(ai.Flag(), SpanFlag::kLow);
  EXPECT_FALSE(ai.Faulted());
  EXPECT_TRUE(ai.Busy());
  ai.Tick(1ms, p, 0.0);
  EXPECT_TRUE(ai.Faulted());
  EXPECT_FALSE(ai.Busy());
  const Signal s = ai.AsSource(p);
  EXPECT_TRUE(s.error);
  EXPECT_EQ(s.min, 500);
  EXPECT_EQ(s.max, 4500);
  EXPECT_EQ(s.decimal_digits, 3);
  ai.Tick(10ms, p, 2.5);
  EXPECT_FALSE(ai.AsSource(p).error);
  EXPECT_EQ(ai.AsSource(p).value, 2500);
}

// A filtered input passing through the span on its way up sets the flag only briefly: no fault.
TEST(AnalogInputTest, FilteredRiseDoesNotFault) {
  AnalogInput ai;
  AnalogInputParams p;
  p.filter = {FilterType::kMovingAverage, 100, {}};
  ai.Tick(2000ms, p, 2.5);
  EXPECT_EQ(ai.Flag(), SpanFlag::kNone);
  EXPECT_FALSE(ai.Faulted());
  EXPECT_EQ(ai.FieldValue(), 2500);
  EXPECT_FALSE(ai.Busy());
}

// Figure 7: PV = S1PV + (FV - S1FV)(S2PV - S1PV)/(S2FV - S1FV); the defaults (PV points = FV
// points) give PV = FV.
TEST(AnalogInputTest, ProcessValueIsLinearThroughTwoPoints) {
  AnalogInput ai;
  AnalogInputParams p;
  ai.Tick(1ms, p, 2.5);
  EXPECT_EQ(ai.ProcessValue(), 2500);
  p.scaling1_pv = 0;
  p.scaling2_pv = 1000;
  ai.Tick(1ms, p, 2.5);
  EXPECT_EQ(ai.ProcessValue(), 500);
  ai.Tick(1ms, p, 4.9);
  EXPECT_EQ(ai.ProcessValue(), 1100);  // not held at the scaling points
  p.scaling2_fv = p.scaling1_fv;
  EXPECT_DOUBLE_EQ(ScaleToProcessValue(p, 1234), 1234);
}

// Table 9: the 2102h shift; 4.2 mA with 0 digits is 4, 123.45 kOhm with 2 digits is 12345.
TEST(AnalogInputTest, DecimalDigitsShiftTheMeasurement) {
  AnalogInput ai;
  AnalogInputParams p;
  p.span.enabled = false;
  p.fv_digits = 0;
  ai.Tick(1ms, p, 4.2);
  EXPECT_EQ(ai.FieldValue(), 4);
  p.fv_digits = 2;
  ai.Tick(1ms, p, 123.45);
  EXPECT_EQ(ai.FieldValue(), 12345);
}

// Table 10 (valve) as data, keyed by 6110h/2100h/2101h/6112h.
TEST(InputDefaultsTest, ValveTable10) {
  const auto v5 = FindInputDefaults(ValveInputDefaults(), *ClassifyInput(40, 0, false, false));
  ASSERT_TRUE(v5);
  EXPECT_EQ(v5->fv_digits, 3);
  EXPECT_EQ(v5->span_start, 200);
  EXPECT_EQ(v5->scaling1, 500);
  EXPECT_EQ(v5->scaling2, 4500);
  EXPECT_EQ(v5->span_end, 4800);
  EXPECT_EQ(v5->hysteresis, 100);
  const auto rpm = FindInputDefaults(ValveInputDefaults(), *ClassifyInput(60, 0, true, false));
  EXPECT_EQ(rpm->span_end, 33000);
  EXPECT_EQ(rpm->fv_digits, 1);
  const auto ohm = FindInputDefaults(ValveInputDefaults(), *ClassifyInput(11000, 0, false, false));
  EXPECT_EQ(ohm->scaling2, 20000);
  EXPECT_EQ(ohm->fv_digits, 2);
  EXPECT_EQ(FindInputDefaults(ValveInputDefaults(), *ClassifyInput(40, 0, false, true))->scaling2, 1);
}

// Valve Table 10 vs logger Table 11: the 0-20 mA rows differ (valve printed 30000/32000/250,
// logger 20/21/1) and the logger has no resistive input.
TEST(InputDefaultsTest, LoggerTable11DiffersFromTheValve) {
  const InputRange ma = *ClassifyInput(50, 0, false, false);
  EXPECT_EQ(FindInputDefaults(ValveInputDefaults(), ma)->scaling2, 30000);
  EXPECT_EQ(FindInputDefaults(DataLoggerInputDefaults(), ma)->scaling2, 20);
  EXPECT_EQ(FindInputDefaults(DataLoggerInputDefaults(), ma)->hysteresis, 1);
  EXPECT_EQ(FindInputDefaults(DataLoggerInputDefaults(), InputRange::kResistive), std::nullopt);
  EXPECT_EQ(FindInputDefaults(DataLoggerInputDefaults(), *ClassifyInput(50, 1, false, false))->span_start, 3);
}

// Table 6: only the listed type/range pairs exist.
TEST(InputDefaultsTest, ClassifyRejectsRangesTable6DoesNotList) {
  EXPECT_EQ(ClassifyInput(40, 1, false, false), InputRange::kVoltage0To10V);
  EXPECT_EQ(ClassifyInput(40, 2, false, false), std::nullopt);
  EXPECT_EQ(ClassifyInput(10000, 1, false, false), std::nullopt);
  EXPECT_EQ(ClassifyInput(60, 0, false, false), InputRange::kFrequency);
  EXPECT_EQ(ClassifyInput(42, 0, false, false), std::nullopt);
}

}  // namespace
}  // namespace canfleet::devices::blocks::test
