// PID: valve UMAX020411A §1.6 Figure 14 and Table 22, §3.3.32-3.3.35, §3.4.49-3.4.57; encoder
// AX023241 §1.8 Table 14.
#include <gtest/gtest.h>

#include <chrono>

#include "node/devices/blocks/pid.hpp"
#include "tests/unit/blocks/fake_sources.hpp"

namespace canfleet::devices::blocks::test {
namespace {

using namespace std::chrono_literals;

Signal Pct(double v) {
  return Ranged(v, 0, 100);
}

// Figure 14 with the object defaults: G 7450h = 5 (0.5), Ki 2451h = 10 (1.0), Kd 2452h = 10,
// Ti 7452h = 5 ms, Td 7454h = 1 ms, cycle 7456h = 10 ms: T = 0.010 s, Pg = 0.5,
// Ig = G*Ki*T/Ti = 1.0, Dg = G*Kd*Td/T = 0.05.
TEST(PidTest, ValveGainsFollowFigure14) {
  const PidGains g = ComputePidGains(PidParams{}, ValvePidProfile());
  EXPECT_DOUBLE_EQ(g.p, 0.5);
  EXPECT_DOUBLE_EQ(g.i, 1.0);
  EXPECT_DOUBLE_EQ(g.d, 0.05);
}

// Encoder §1.8: I_Gain = Ki*T/Ti and D_Gain = Kd*Td/T without G, and T = 0.001 whatever the cycle.
TEST(PidTest, EncoderGainsUseAFixedPeriodAndNoGainFactor) {
  const PidGains g = ComputePidGains(PidParams{}, EncoderPidProfile());
  EXPECT_DOUBLE_EQ(g.p, 0.5);
  EXPECT_DOUBLE_EQ(g.i, 0.2);
  EXPECT_DOUBLE_EQ(g.d, 1.0);
}

// Figure 14 note: "If Ti is zero, I_Gain = 0" (both manuals).
TEST(PidTest, ZeroIntegralTimeDisablesTheIntegralTerm) {
  PidParams params;
  params.ti = 0ms;
  EXPECT_DOUBLE_EQ(ComputePidGains(params, ValvePidProfile()).i, 0.0);
  EXPECT_DOUBLE_EQ(ComputePidGains(params, EncoderPidProfile()).i, 0.0);
}

// Figure 14 worked through with the defaults: target 60 %, feedback 50 %: E = 10,
// cycle 1: S = 10, out = 10*0.5 + 10*1.0 + (10-0)*0.05 = 15.5 %; cycle 2: S = 20, out = 25 %.
// 2460h holds 0.1 % units.
TEST(PidTest, OutputFollowsTheFormulaOfFigure14) {
  Pid pid;
  const PidParams params;
  EXPECT_EQ(pid.Step(params, Pct(60), Pct(50)).value, 155);
  EXPECT_DOUBLE_EQ(pid.OutputPercent(), 15.5);
  EXPECT_EQ(pid.Step(params, Pct(60), Pct(50)).value, 250);
  EXPECT_DOUBLE_EQ(pid.ErrorSum(), 20.0);
  EXPECT_EQ(pid.Output().max, 1000);
  EXPECT_EQ(pid.Output().decimal_digits, 1);
}

// §3.4.49: an absolute error below 2450h (default 10 = 1.0 %) "will be interpreted as zero".
TEST(PidTest, ToleranceTreatsSmallErrorsAsZero) {
  Pid pid;
  const PidParams params;
  pid.Step(params, Pct(50.9), Pct(50));
  EXPECT_DOUBLE_EQ(pid.Error(), 0.0);
  EXPECT_EQ(pid.Output().value, 0);
  pid.Step(params, Pct(51), Pct(50));
  EXPECT_DOUBLE_EQ(pid.Error(), 1.0);
}

// §1.6: target and feedback are normalised with their sources' limits; a constant target has none
// and borrows the feedback's: constant 2500 against an AI in 500..4500 mV is 50 %.
TEST(PidTest, ConstantTargetUsesTheFeedbackLimits) {
  Pid pid;
  pid.Step(PidParams{}, Signal::Constant(2500), Ranged(500, 500, 4500, 3));
  EXPECT_DOUBLE_EQ(pid.Error(), 50.0);
}

// §3.4.57 "a value between 0 to 100%": the output is clamped, and the error sum stops where the
// output reaches the limit (our anti-windup), so it leaves 100 % on the first cycle the error
// changes sign instead of unwinding 100 cycles of error.
TEST(PidTest, OutputIsClampedWithoutWindup) {
  Pid pid;
  const PidParams params;
  for (int i = 0; i < 100; ++i)
    pid.Step(params, Pct(100), Pct(50));
  EXPECT_EQ(pid.Output().value, 1000);
  EXPECT_DOUBLE_EQ(pid.ErrorSum(), 75.0);  // 50*0.5 + 75*1.0 = 100 %
  pid.Step(params, Pct(40), Pct(50));      // E = -10: -5 + 65 - 3 = 57 %
  EXPECT_EQ(pid.Output().value, 570);

  Pid low;
  for (int i = 0; i < 100; ++i)
    low.Step(params, Pct(0), Pct(50));
  EXPECT_EQ(low.Output().value, 0);
  EXPECT_DOUBLE_EQ(low.ErrorSum(), 0.0);  // P = -25 % is below 0 already: S never integrates
}

// Table 22: push-pull pair. Over target (feedback 60 > target 50, E = -10) the "on when over"
// output drives 15.5 % and the "on when below" output is off; below target the reverse.
TEST(PidTest, PushPullResponsesEachShowTheirHalf) {
  PidParams over;
  over.response = PidResponse::kOnWhenOverTarget;
  PidParams below;
  below.response = PidResponse::kOnWhenBelowTarget;
  Pid a;
  Pid b;
  EXPECT_EQ(a.Step(over, Pct(50), Pct(60)).value, 155);
  EXPECT_EQ(b.Step(below, Pct(50), Pct(60)).value, 0);
  Pid c;
  Pid d;
  EXPECT_EQ(c.Step(over, Pct(60), Pct(50)).value, 0);
  EXPECT_EQ(d.Step(below, Pct(60), Pct(50)).value, 155);
  Pid single;
  EXPECT_EQ(single.Step(PidParams{}, Pct(50), Pct(60)).value, 0);  // single output: 0..100 % only
}

// Valve Table 22 (0 single, 1 over, 2 below) vs encoder Table 14 (0 single, 1 setpoint, 2 over,
// 3 below).
TEST(PidTest, ResponseCodesDifferPerProduct) {
  EXPECT_EQ(ValvePidProfile().DecodeResponse(1), PidResponse::kOnWhenOverTarget);
  EXPECT_EQ(ValvePidProfile().DecodeResponse(3), std::nullopt);
  EXPECT_EQ(EncoderPidProfile().DecodeResponse(1), PidResponse::kSetpointControl);
  EXPECT_EQ(EncoderPidProfile().DecodeResponse(3), PidResponse::kOnWhenBelowTarget);
}

// §3.4.52: "A selection of 'Control Source Not Used' disables the associated PID": output 0 and
// the state starts over.
TEST(PidTest, UnusedSourceDisablesTheLoop) {
  Pid pid;
  pid.Step(PidParams{}, Pct(60), Pct(50));
  pid.Step(PidParams{}, Signal::NotAvailable(), Pct(50));
  EXPECT_FALSE(pid.Enabled());
  EXPECT_EQ(pid.Output().value, 0);
  EXPECT_DOUBLE_EQ(pid.ErrorSum(), 0.0);
  EXPECT_FALSE(pid.Busy());
}

// §4 "If an error on the input is detected, the output of the controller shuts off" is the
// output block's job (6340h); the PID holds its value, flags the error and does not integrate.
TEST(PidTest, FaultedInputHoldsTheOutputAndFlagsIt) {
  Pid pid;
  pid.Step(PidParams{}, Pct(60), Pct(50));
  const Signal& out = pid.Step(PidParams{}, Pct(60), Faulted(Pct(50)));
  EXPECT_TRUE(out.error);
  EXPECT_EQ(out.value, 155);
  EXPECT_DOUBLE_EQ(pid.ErrorSum(), 10.0);
  EXPECT_FALSE(pid.Step(PidParams{}, Pct(60), Pct(50)).error);
}

// §1.6 "the PID algorithm will be called every 7456h PID Cycle Time": ticks shorter than the cycle
// accumulate; a long tick runs one cycle per period.
TEST(PidTest, TickRunsOneCyclePerPeriod) {
  Pid pid;
  const PidParams params;  // 10 ms
  pid.Tick(5ms, params, Pct(60), Pct(50));
  EXPECT_EQ(pid.Output().value, 0);
  EXPECT_EQ(pid.NextStepAfter(params), 5ms);
  pid.Tick(5ms, params, Pct(60), Pct(50));
  EXPECT_EQ(pid.Output().value, 155);
  pid.Tick(30ms, params, Pct(60), Pct(50));
  EXPECT_DOUBLE_EQ(pid.ErrorSum(), 40.0);
}

// Busy(): once E has been 0 for two cycles the output cannot change while the inputs do not.
TEST(PidTest, SettledLoopIsNotBusy) {
  Pid pid;
  const PidParams params;
  pid.Step(params, Pct(60), Pct(50));
  EXPECT_TRUE(pid.Busy());
  pid.Step(params, Pct(50), Pct(50));
  EXPECT_TRUE(pid.Busy());  // D term still moves: E went 10 -> 0
  const double held = pid.OutputPercent();
  pid.Step(params, Pct(50), Pct(50));
  EXPECT_FALSE(pid.Busy());
  pid.Step(params, Pct(50), Pct(50));
  EXPECT_DOUBLE_EQ(pid.OutputPercent(), 10.0);  // S = 10: I term only
  EXPECT_NE(held, pid.OutputPercent());
}

}  // namespace
}  // namespace canfleet::devices::blocks::test
