// Lookup tables: valve UMAX020411A §1.7 (Tables 17, 23), logger UMAX181001 §1.5, encoder
// AX023241 §1.6 and §C3-1.4.42.
#include <gtest/gtest.h>

#include <chrono>
#include <vector>

#include "node/devices/blocks/lookup_table.hpp"
#include "tests/unit/blocks/fake_sources.hpp"

namespace canfleet::devices::blocks::test {
namespace {

using namespace std::chrono_literals;
using R = PointResponse;

Signal X(double v) {
  return Ranged(v, 0, 100);
}
Signal On() {
  return Ranged(1, 0, 1);
}
Signal Off() {
  return Ranged(0, 0, 1);
}

LookupTableParams Table(std::vector<LutPoint> points) {
  LookupTableParams p;
  p.points = std::move(points);
  return p;
}

// §1.7.3: "a simple linear response from 0 to 100 in steps of 10 for both the X and Y axes",
// output held at Y1 below X1 and at Y11 above X11 (all three products have 11 points).
TEST(LookupTableTest, DefaultTableIsALinearRampHeldAtTheEnds) {
  for (const LookupTableProfile& profile :
       {ValveLookupTableProfile(), EncoderLookupTableProfile(), DataLoggerLookupTableProfile()}) {
    const LookupTableParams p = DefaultLookupTableParams(profile);
    ASSERT_EQ(p.points.size(), 11u);
    EXPECT_DOUBLE_EQ(EvaluateData(p.points, 15), 15);
    EXPECT_DOUBLE_EQ(EvaluateData(p.points, 97.5), 97.5);
    EXPECT_DOUBLE_EQ(EvaluateData(p.points, -5), 0);
    EXPECT_DOUBLE_EQ(EvaluateData(p.points, 150), 100);
  }
}

// §1.7.3 Figure 16 "Step" response: any input in (X[N-1], X[N]] gives Y[N].
TEST(LookupTableTest, JumpToGivesTheNextPointsY) {
  LookupTableParams p = DefaultLookupTableParams(ValveLookupTableProfile());
  for (LutPoint& pt : p.points)
    pt.response = R::kJumpTo;
  EXPECT_DOUBLE_EQ(EvaluateData(p.points, 0), 0);
  EXPECT_DOUBLE_EQ(EvaluateData(p.points, 0.5), 10);
  EXPECT_DOUBLE_EQ(EvaluateData(p.points, 10), 10);
  EXPECT_DOUBLE_EQ(EvaluateData(p.points, 15), 20);
  EXPECT_DOUBLE_EQ(EvaluateData(p.points, 100), 100);
}

// §1.7.3: "If ... sub-index N is set to Ignore, then all points from (XN, YN) to (X11, Y11) will
// also be ignored. For all data greater than XN-1, the output ... will be YN-1." Point 1 "cannot"
// be ignored.
TEST(LookupTableTest, IgnoreCutsTheTableAndPointOneIsNeverIgnored) {
  LookupTableParams p = DefaultLookupTableParams(ValveLookupTableProfile());
  p.points[5].response = R::kIgnore;  // point 6 (X = 50)
  p.points[8].response = R::kJumpTo;  // beyond the cut: no effect
  EXPECT_EQ(UsedPointCount(p.points), 5u);
  EXPECT_DOUBLE_EQ(EvaluateData(p.points, 35), 35);
  EXPECT_DOUBLE_EQ(EvaluateData(p.points, 45), 40);
  EXPECT_DOUBLE_EQ(EvaluateData(p.points, 90), 40);

  LookupTableParams q = DefaultLookupTableParams(ValveLookupTableProfile());
  q.points[0].response = R::kIgnore;
  EXPECT_EQ(UsedPointCount(q.points), 11u);
  EXPECT_DOUBLE_EQ(EvaluateData(q.points, 55), 55);
}

// §1.7.3 Figure 17 / logger Figure 10: one joystick on the X axis of two tables that mirror each
// other around a deadband (the figure's numbers are lost; 45..55 % is the deadband here).
TEST(LookupTableTest, MirroredTablesGiveAJoystickDeadband) {
  const LookupTableParams lower = Table({{0, 100}, {45, 0, R::kRampTo}, {50, 0, R::kIgnore}});
  const LookupTableParams upper =
      Table({{0, 0}, {55, 0, R::kJumpTo}, {100, 100, R::kRampTo}, {100, 100, R::kIgnore}});
  EXPECT_DOUBLE_EQ(EvaluateData(lower.points, 0), 100);
  EXPECT_DOUBLE_EQ(EvaluateData(lower.points, 22.5), 50);
  EXPECT_DOUBLE_EQ(EvaluateData(lower.points, 50), 0);
  EXPECT_DOUBLE_EQ(EvaluateData(upper.points, 50), 0);
  EXPECT_DOUBLE_EQ(EvaluateData(upper.points, 77.5), 50);
  EXPECT_DOUBLE_EQ(EvaluateData(upper.points, 100), 100);
}

// §1.7.1: X1 <= X2 <= ... <= X11 over the points in use.
TEST(LookupTableTest, XAxisMustNotDecreaseOverUsedPoints) {
  LookupTableParams p = DefaultLookupTableParams(ValveLookupTableProfile());
  EXPECT_TRUE(XAxisNonDecreasing(p.points));
  p.points[9].x = 5;
  EXPECT_FALSE(XAxisNonDecreasing(p.points));
  p.points[8].response = R::kIgnore;
  EXPECT_TRUE(XAxisNonDecreasing(p.points));
}

// Valve/logger §1.7.2: 0..100 while all Y are within 0..100, else lowest..highest Y, ignored points
// included; Table 17 widens to include 0 and 100; encoder §1.6.2 uses only the points in use.
TEST(LookupTableTest, OutputRangeRulesDifferPerProduct) {
  LookupTableParams p = Table({{0, 20}, {10, 60}, {20, 80}});
  EXPECT_EQ(OutputRange(p.points, YRangeRule::kPercentUnlessOutside), std::make_pair(0.0, 100.0));
  p.points[2].y = 150;
  EXPECT_EQ(OutputRange(p.points, YRangeRule::kPercentUnlessOutside), std::make_pair(20.0, 150.0));
  EXPECT_EQ(OutputRange(p.points, YRangeRule::kWidenedToPercent), std::make_pair(0.0, 150.0));
  p.points[2].response = R::kIgnore;
  EXPECT_EQ(OutputRange(p.points, YRangeRule::kPercentUnlessOutside), std::make_pair(20.0, 150.0));
  EXPECT_EQ(OutputRange(p.points, YRangeRule::kUsedPointsOnly), std::make_pair(20.0, 60.0));
  EXPECT_EQ(ValveLookupTableProfile().y_range, YRangeRule::kPercentUnlessOutside);
  EXPECT_EQ(EncoderLookupTableProfile().y_range, YRangeRule::kUsedPointsOnly);
}

// Valve Table 23: sub 2-11 0 ignore, 1 ramp, 2 jump; encoder §C3-1.4.42: 0 ramp, 1 jump; time
// points up to 24 h (valve/logger §1.7.4) or 1 min (encoder §1.6.5).
TEST(LookupTableTest, PointResponseCodesDifferPerProduct) {
  const LookupTableProfile valve = ValveLookupTableProfile();
  const LookupTableProfile encoder = EncoderLookupTableProfile();
  EXPECT_EQ(valve.DecodeResponse(0), R::kIgnore);
  EXPECT_EQ(valve.DecodeResponse(2), R::kJumpTo);
  EXPECT_EQ(valve.DecodeResponse(3), std::nullopt);
  EXPECT_EQ(encoder.DecodeResponse(0), R::kRampTo);
  EXPECT_EQ(encoder.DecodeResponse(1), R::kJumpTo);
  EXPECT_EQ(encoder.DecodeResponse(2), std::nullopt);
  EXPECT_EQ(valve.max_time_interval, 86'400'000ms);
  EXPECT_EQ(encoder.max_time_interval, 60'000ms);
}

// §1.8.3 / Table 17: the output signal carries the Y range, the Y digits and the X source's state;
// a table without an X-axis source is "Not Available".
TEST(LookupTableTest, OutputSignalCarriesRangeAndSourceState) {
  LookupTable lut;
  LookupTableParams p = Table({{0, -50}, {100, 150}});
  p.y_digits = 1;
  const Signal& out = lut.Update(p, X(50), 10ms);
  EXPECT_EQ(out.value, 50);
  EXPECT_EQ(out.min, -50);
  EXPECT_EQ(out.max, 150);
  EXPECT_EQ(out.decimal_digits, 1);
  EXPECT_TRUE(out.available);
  EXPECT_DOUBLE_EQ(out.ToPercent(), 50.0);
  EXPECT_TRUE(lut.Update(p, Faulted(X(50)), 10ms).error);
  EXPECT_FALSE(lut.Update(p, Signal::NotAvailable(), 10ms).available);
  EXPECT_FALSE(lut.Busy());  // a data response changes only with its input
}

// A time profile: 0 -> 100 over 100 ms (ramp), then 40 for 50 ms (jump). X are intervals.
LookupTableParams TimeProfile(bool repeat) {
  LookupTableParams p = Table({{0, 0}, {100, 100, R::kRampTo}, {50, 40, R::kJumpTo}, {1, 0, R::kIgnore}});
  p.x_axis_type = XAxisType::kTime;
  p.auto_repeat = repeat;
  return p;
}

// Runs `lut` for `ticks` ticks of `period` with the input ON; returns the outputs.
std::vector<double> PlayOn(LookupTable& lut, const LookupTableParams& p, int ticks,
                           std::chrono::milliseconds period) {
  std::vector<double> out;
  for (int i = 0; i < ticks; ++i)
    out.push_back(lut.Update(p, On(), period).value);
  return out;
}

// §1.7.4: OFF -> 0; ON starts at (X1, Y1) = 0 ms; the profile plays; at the end the output holds
// the last value until OFF (auto repeat FALSE); the next ON starts over.
TEST(LookupTableTest, TimeResponsePlaysOnceAndHolds) {
  LookupTable lut;
  const LookupTableParams p = TimeProfile(false);
  EXPECT_EQ(lut.Update(p, Off(), 10ms).value, 0);
  EXPECT_EQ(PlayOn(lut, p, 18, 10ms),
            (std::vector<double>{0, 10, 20, 30, 40, 50, 60, 70, 80, 90, 100, 40, 40, 40, 40, 40, 40, 40}));
  EXPECT_FALSE(lut.Busy());
  EXPECT_EQ(lut.Update(p, On(), 1000ms).value, 40);
  EXPECT_EQ(lut.Update(p, Off(), 10ms).value, 0);
  EXPECT_EQ(lut.Update(p, On(), 10ms).value, 0);
  EXPECT_EQ(lut.Update(p, On(), 25ms).value, 25);
}

// §1.7.4: with auto repeat the table "will revert back to the first point in the table and Auto
// Repeat the sequence" for as long as the input is ON; OFF stops it at 0.
TEST(LookupTableTest, TimeResponseAutoRepeats) {
  LookupTable lut;
  const LookupTableParams p = TimeProfile(true);
  EXPECT_EQ(PlayOn(lut, p, 17, 10ms),
            (std::vector<double>{0, 10, 20, 30, 40, 50, 60, 70, 80, 90, 100, 40, 40, 40, 40, 0, 10}));
  // Many cycles later, still on the same 150 ms period: 150 * 100 + 30 ms in.
  EXPECT_EQ(lut.Update(p, On(), 15'020ms).value, 30);
  EXPECT_TRUE(lut.Busy());
  EXPECT_EQ(lut.Update(p, Off(), 10ms).value, 0);
  EXPECT_FALSE(lut.Busy());
}

// §1.7.4 "The interval time between each point": the default reads X as intervals; absolute times
// give the same profile from X = 0, 100, 150.
TEST(LookupTableTest, TimeAxisCanBeAbsolute) {
  LookupTableProfile profile = ValveLookupTableProfile();
  profile.time_mode = TimeAxisMode::kAbsolute;
  LookupTable lut(profile);
  LookupTableParams p = TimeProfile(false);
  p.points[2].x = 150;
  EXPECT_EQ(PlayOn(lut, p, 13, 10ms),
            (std::vector<double>{0, 10, 20, 30, 40, 50, 60, 70, 80, 90, 100, 40, 40}));
}

// NextChangeAfter: 0 while ramping, the rest of a jump segment, nullopt when holding or OFF, so a
// caller can stop ticking.
TEST(LookupTableTest, NextChangeAfterTellsWhenToTickAgain) {
  LookupTable lut;
  LookupTableParams p = TimeProfile(false);
  lut.Update(p, On(), 10ms);
  EXPECT_EQ(lut.NextChangeAfter(), 0ms);
  lut.Update(p, On(), 110ms);  // t = 110: inside the jump segment (100, 150]
  EXPECT_EQ(lut.Output().value, 40);
  EXPECT_EQ(lut.NextChangeAfter(), 40ms);
  lut.Update(p, On(), 40ms);  // t = 150: end
  EXPECT_EQ(lut.NextChangeAfter(), std::nullopt);
  lut.Update(p, Off(), 10ms);
  EXPECT_EQ(lut.NextChangeAfter(), std::nullopt);

  p.auto_repeat = true;
  lut.Update(p, On(), 10ms);
  lut.Update(p, On(), 140ms);              // t = 140
  EXPECT_EQ(lut.NextChangeAfter(), 10ms);  // then back to point 1
  lut.Update(p, On(), 10ms);
  EXPECT_EQ(lut.Output().value, 0);
}

// §1.7.4: the X source "is treated as a digital input": a faulted or absent source is OFF.
TEST(LookupTableTest, TimeResponseTreatsFaultedInputAsOff) {
  LookupTable lut;
  const LookupTableParams p = TimeProfile(false);
  PlayOn(lut, p, 5, 10ms);
  const Signal& out = lut.Update(p, Faulted(On()), 10ms);
  EXPECT_EQ(out.value, 0);
  EXPECT_TRUE(out.error);
  EXPECT_EQ(lut.ProfileTime(), 0ms);
}

}  // namespace
}  // namespace canfleet::devices::blocks::test
