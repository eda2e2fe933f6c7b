// (source, number) wiring and the Signal seen by consumers: valve UMAX020411A §1.5 Tables 15-17,
// encoder AX023241 §1.3 Tables 6-7, logger UMAX181001 §1.4 Tables 13-15.
#include <gtest/gtest.h>

#include "node/devices/blocks/control_source.hpp"
#include "tests/unit/blocks/fake_sources.hpp"

namespace canfleet::devices::blocks::test {
namespace {

// Valve Table 16: RPDO 1-24 (7300h 1-8, 6200h 9-12, 2500h 13-24), AI 1-12, constants 1-15, PID
// 1-4, LUT 1-12, math 1-6, logic 1-4, outputs 1-12; no source 12.
TEST(ControlSourceTest, ValveNumberRangesFollowTable16) {
  const ControlSources valve(ValveSourceTypes(), nullptr);
  EXPECT_TRUE(valve.IsAllowed({1, 24}));
  EXPECT_FALSE(valve.IsAllowed({1, 25}));
  EXPECT_FALSE(valve.IsAllowed({1, 0}));
  EXPECT_TRUE(valve.IsAllowed({2, 12}));
  EXPECT_FALSE(valve.IsAllowed({2, 13}));
  EXPECT_TRUE(valve.IsAllowed({3, 15}));
  EXPECT_FALSE(valve.IsAllowed({4, 5}));
  EXPECT_TRUE(valve.IsAllowed({5, 12}));
  EXPECT_FALSE(valve.IsAllowed({6, 7}));
  EXPECT_TRUE(valve.IsAllowed({7, 4}));
  EXPECT_TRUE(valve.IsAllowed({9, 12}));
  EXPECT_FALSE(valve.IsAllowed({12, 1}));
  EXPECT_FALSE(valve.IsSourceAllowed(12));
  EXPECT_TRUE(valve.IsSourceAllowed(11));
}

// Valve §3.4.52-3.4.53: PID target source defaults to 0 with number x, so "not used" accepts any
// number; Table 16 gives supply and temperature numbers as "N/A".
TEST(ControlSourceTest, NotUsedAndNotApplicableNumbersAreIgnored) {
  const ControlSources valve(ValveSourceTypes(), nullptr);
  EXPECT_TRUE(valve.IsAllowed({0, 3}));
  EXPECT_TRUE(valve.IsAllowed({10, 0}));
  EXPECT_TRUE(valve.IsAllowed({11, 7}));
  EXPECT_TRUE(valve.Find(8)->diagnostic_only);
  EXPECT_FALSE(valve.Find(2)->diagnostic_only);
}

// Encoder Table 6/7: different codes and much smaller ranges; supply and temperature are numbered
// [1...1].
TEST(ControlSourceTest, EncoderNumberingFollowsTables6And7) {
  const ControlSources encoder(EncoderSourceTypes(), nullptr);
  EXPECT_EQ(encoder.KindOf(8), SourceKind::kPid);
  EXPECT_EQ(encoder.KindOf(9), SourceKind::kConstant);
  EXPECT_EQ(encoder.KindOf(10), SourceKind::kSetReset);
  EXPECT_TRUE(encoder.IsAllowed({1, 5}));
  EXPECT_FALSE(encoder.IsAllowed({1, 6}));
  EXPECT_TRUE(encoder.IsAllowed({8, 1}));
  EXPECT_FALSE(encoder.IsAllowed({8, 2}));
  EXPECT_TRUE(encoder.IsAllowed({9, 10}));
  EXPECT_FALSE(encoder.IsAllowed({9, 11}));
  EXPECT_TRUE(encoder.IsAllowed({13, 1}));
  EXPECT_FALSE(encoder.IsAllowed({13, 2}));
  EXPECT_FALSE(encoder.IsSourceAllowed(14));
  EXPECT_EQ(encoder.CodeOf(SourceKind::kLookupTable), 5);
  EXPECT_EQ(encoder.CodeOf(SourceKind::kThermocouple), std::nullopt);
}

// Logger Table 13/14 (list order): thermocouple sources 3 and 4, constants at 5, logic at 8.
TEST(ControlSourceTest, DataLoggerNumberingFollowsTables13And14) {
  const ControlSources logger(DataLoggerSourceTypes(), nullptr);
  EXPECT_EQ(logger.KindOf(3), SourceKind::kColdJunction);
  EXPECT_EQ(logger.KindOf(4), SourceKind::kThermocouple);
  EXPECT_EQ(logger.KindOf(5), SourceKind::kConstant);
  EXPECT_EQ(logger.KindOf(8), SourceKind::kLogic);
  EXPECT_TRUE(logger.IsAllowed({1, 12}));
  EXPECT_FALSE(logger.IsAllowed({1, 13}));
  EXPECT_TRUE(logger.IsAllowed({2, 10}));
  EXPECT_FALSE(logger.IsAllowed({2, 11}));
  EXPECT_TRUE(logger.IsAllowed({4, 4}));
  EXPECT_FALSE(logger.IsAllowed({4, 5}));
  EXPECT_TRUE(logger.IsAllowed({10, 9}));
  EXPECT_FALSE(logger.IsSourceAllowed(11));
}

// The same kind resolves through each product's own code: PID is 4 on the valve, 8 on the encoder.
TEST(ControlSourceTest, ResolveMapsCodesToKindsPerProduct) {
  FakeSources valve(ValveSourceTypes());
  FakeSources encoder(EncoderSourceTypes());
  valve.Set(SourceKind::kPid, 1, Signal::Percent(25.0));
  encoder.Set(SourceKind::kPid, 1, Signal::Percent(75.0));
  EXPECT_EQ(valve.sources().Resolve({4, 1}).value, 250);
  EXPECT_EQ(encoder.sources().Resolve({8, 1}).value, 750);
  EXPECT_FALSE(encoder.sources().Resolve({4, 1}).available);  // encoder 4 = output feedback, unset
}

// Table 15 "Control Source Not Used (Ignored)" and pairs outside Table 16 never reach the product.
TEST(ControlSourceTest, NotUsedAndInvalidPairsAreNotAvailable) {
  FakeSources valve(ValveSourceTypes());
  valve.Set(SourceKind::kAnalogInput, 13, Ranged(1, 0, 1));
  EXPECT_FALSE(valve.sources().Resolve({0, 1}).available);
  EXPECT_FALSE(valve.sources().Resolve({2, 13}).available);
  EXPECT_FALSE(valve.sources().Resolve({42, 1}).available);
  EXPECT_EQ(valve.reads(), 0);
}

// Table 17: consumers normalise with the source's Scaling 1/2; AI 2500 mV in 500..4500 mV = 50 %.
TEST(SignalTest, ToPercentUsesTheSourceLimitsAndHoldsAtTheEnds) {
  EXPECT_DOUBLE_EQ(Ranged(2500, 500, 4500, 3).ToPercent(), 50.0);
  EXPECT_DOUBLE_EQ(Ranged(100, 500, 4500, 3).ToPercent(), 0.0);
  EXPECT_DOUBLE_EQ(Ranged(9000, 500, 4500, 3).ToPercent(), 100.0);
  EXPECT_DOUBLE_EQ(Ranged(25, 100, 0).ToPercent(), 75.0);  // inverse limits
  EXPECT_DOUBLE_EQ(Ranged(5, 7, 7).ToPercent(), 0.0);      // empty range
  EXPECT_DOUBLE_EQ(Signal::Constant(42.0).ToPercent(), 42.0);
  const Signal pid = Signal::Percent(12.34);  // 2460h: 1 decimal
  EXPECT_EQ(pid.value, 123);
  EXPECT_EQ(pid.max, 1000);
  EXPECT_EQ(pid.decimal_digits, 1);
}

}  // namespace
}  // namespace canfleet::devices::blocks::test
