// The quadrature encoder of the AX023241 (1.2, Figure 2, Table 3, C3-1.4.46-1.4.49): the shaft
// model, the x4 step counter with its 32-bit wrap, scaling (3410h-3413h), and the device counting a
// known speed for a known simulated time without waking while nothing consumes the count.
#include <cstdint>

#include "node/devices/encoder_dual_valve/quadrature.hpp"
#include "tests/unit/encoder/encoder_fixture.hpp"

namespace canfleet::devices::encoder::test {
namespace {

TimePoint At(Duration d) {
  return TimePoint{} + d;
}

// 1.2 / README "Encoder": position advances at the velocity; an edge is passed half-way between
// two whole positions, so both directions round alike.
TEST(ShaftTest, PositionIsVelocityTimesTimeAndEdgesRoundToTheNearest) {
  Shaft shaft;
  shaft.SetVelocity(At(0ms), 160.0);
  EXPECT_EQ(shaft.EdgesAt(At(1500ms)), 240);
  shaft.SetVelocity(At(1500ms), -160.0);
  EXPECT_EQ(shaft.EdgesAt(At(2000ms)), 160);
  shaft.MoveTo(At(2000ms), -0.6);
  EXPECT_EQ(shaft.EdgesAt(At(2000ms)), -1);
  shaft.MoveTo(At(2000ms), -0.4);
  shaft.SetVelocity(At(2000ms), 0.0);
  EXPECT_EQ(shaft.EdgesAt(At(9000ms)), 0);
}

// README "Encoder": the step counter is a 32-bit two's-complement register that wraps.
TEST(StepCounterTest, WrapsAtThirtyTwoBits) {
  StepCounter counter;
  counter.Zero(10);
  EXPECT_EQ(counter.Steps(10), 0);
  EXPECT_EQ(counter.Steps(9), -1);
  EXPECT_EQ(counter.Steps(10 + 0x7FFFFFFFLL), 0x7FFFFFFF);
  EXPECT_EQ(counter.Steps(10 + 0x80000000LL), INT32_MIN);
  EXPECT_EQ(counter.Steps(10 + 0x80000005LL), INT32_MIN + 5);
  EXPECT_EQ(counter.Steps(10 + 0x100000000LL), 0);
}

// C3-1.4.46-1.4.49: scaler, direction, step offset; speed from pulses per revolution (x4).
TEST(QuadratureScalingTest, ScalerDirectionOffsetAndSpeed) {
  QuadratureParams q;
  EXPECT_EQ(ScaledCount(100, q), 100.0);
  q.scaler = 0.5;
  q.inverted = true;
  q.offset = 10;
  EXPECT_EQ(ScaledCount(100, q), -45.0);
  q.pulses_per_rev = 4;
  EXPECT_EQ(SpeedRpm(160.0, q), 600.0);
  EXPECT_EQ(SpeedRpm(-160.0, q), 600.0);
  q.pulses_per_rev = 0;
  EXPECT_EQ(SpeedRpm(160.0, q), 0.0);
  EXPECT_EQ(EdgesPerSecond(600.0, 4.0), 160.0);
}

class QuadratureDeviceTest : public EncoderTest {};

// 1.2, Table 3: 600 rpm on a 4-pulse encoder (3413h = 4) for 1.5 s is 240 steps (x4) on input 1
// (2100h = 0, edge count) and 600 rpm on input 2 (2100h = 2, speed). Nothing consumes the moving
// count, so the device does not wake while the shaft turns: 7100h is sampled when read.
TEST_F(QuadratureDeviceTest, KnownSpeedForKnownTimeGivesCountAndSpeed) {
  Write(0x2100, 2, 2, 1);
  Advance(10ms);
  SetNumber("ENC.speed_rpm", 600);
  Advance(10ms);
  const auto evaluations = device().Evaluations();
  EXPECT_FALSE(device().Ticking());
  Advance(1490ms);
  EXPECT_EQ(device().Evaluations(), evaluations);
  EXPECT_EQ(Read(0x7100, 1, true), 240);
  EXPECT_EQ(Read(0x7100, 2, true), 600);
  EXPECT_EQ(Read(0x7130, 1, true), 240);  // PV = FV: 7120h-7123h are 0 (C3-1.3.7-1.3.10)
}

// C3-1.2.20/1.2.24: TPDO1 (event timer 100 ms) carries 7100h.1 and 7100h.2, sampled as it is sent.
TEST_F(QuadratureDeviceTest, Tpdo1CarriesTheCountAsItIsSent) {
  Write(0x2100, 2, 2, 1);
  SetNumber("ENC.speed_rpm", 600);
  Start();
  Advance(200ms);
  EXPECT_EQ(Frames("185#"), (std::vector<std::string>{"185#10005802", "185#20005802"}));
}

// 1.2: "direction/polarity of rotation": reverse counts down; 3411h = 1 inverts; 2100h = 1 gives
// the direction (1 = counting up) and keeps it when the shaft stops.
TEST_F(QuadratureDeviceTest, ReverseCountsDownAndDirectionIsReported) {
  Write(0x2100, 2, 1, 1);
  EXPECT_EQ(Read(0x7100, 2, true), 0);  // power-on: no movement yet
  SetEnum("ENC.direction", "reverse");
  SetNumber("ENC.speed_rpm", 150);  // 40 edges/s
  Advance(1000ms);
  EXPECT_EQ(Read(0x7100, 1, true), -40);
  EXPECT_EQ(Read(0x7100, 2, true), 0);
  SetEnum("ENC.direction", "forward");
  Advance(500ms);
  EXPECT_EQ(Read(0x7100, 1, true), -20);
  EXPECT_EQ(Read(0x7100, 2, true), 1);
  SetNumber("ENC.speed_rpm", 0);
  Advance(10ms);
  EXPECT_EQ(Read(0x7100, 2, true), 1);
  Write(0x3411, 0, 1, 2);
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), 20);
  EXPECT_EQ(Read(0x7100, 2, true), 0);
}

// C3-1.4.46-1.4.48: count = 3410h x (steps + 3412h), with the direction of 3411h.
TEST_F(QuadratureDeviceTest, ScalerAndOffsetApply) {
  SetNumber("ENC.position_counts", 100);
  Write(0x3410, 0, Real32Bits(0.5F), 4);
  Write(0x3412, 0, 10, 4);
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), 55);
  Write(0x3411, 0, 1, 2);
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), -45);
}

// README "Encoder": 7100h (INTEGER16) saturates while the 32-bit counter keeps counting.
TEST_F(QuadratureDeviceTest, CountSaturatesInTheSixteenBitObject) {
  SetNumber("ENC.position_counts", 40000);
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), 32767);
  SetNumber("ENC.position_counts", -40000);
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), -32768);
  SetNumber("ENC.position_counts", 1234);
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), 1234);
}

// README "Encoder": the raw A/B channel frequencies turn the shaft at 4 edges per cycle of the
// slower channel (a channel that lags lets the other's edges count up and down in turn).
TEST_F(QuadratureDeviceTest, RawChannelFrequenciesDriveTheCounter) {
  SetEnum("ENC.drive", "channels");
  SetNumber("IN1.frequency_Hz", 100);
  SetNumber("IN2.frequency_Hz", 100);
  Advance(1000ms);
  EXPECT_EQ(Read(0x7100, 1, true), 400);
  SetNumber("IN2.frequency_Hz", 50);
  Advance(1000ms);
  EXPECT_EQ(Read(0x7100, 1, true), 600);
  SetEnum("ENC.drive", "counts");
  SetNumber("ENC.speed_counts_s", 1000);
  Advance(100ms);
  EXPECT_EQ(Read(0x7100, 1, true), 700);
}

// 1.2.1: "Both inputs need to be configured as one of the Quadrature Encoder input types"; a
// write of 6110h/2100h restarts the counter.
TEST_F(QuadratureDeviceTest, BothInputsMustBeQuadratureAndReconfigurationRestartsTheCount) {
  SetNumber("ENC.position_counts", 500);
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), 500);
  Write(0x6110, 2, 60, 2);
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), 0);
  Write(0x6110, 2, 10002, 2);
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), 0);
  SetNumber("ENC.position_counts", 520);
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), 20);
}

// Table 3 speed with 2102h decimals: 600 rpm with 1 decimal is 6000; 3413h must be at least 1.
TEST_F(QuadratureDeviceTest, SpeedUsesDecimalDigitsAndPulsesPerRevolution) {
  Write(0x2100, 1, 2, 1);
  Write(0x2102, 1, 1, 1);
  SetNumber("ENC.speed_rpm", 600);
  Advance(2ms);
  EXPECT_EQ(Read(0x7100, 1, true), 6000);
  Write(0x3413, 0, 8, 4);  // the device now thinks 8 pulses per revolution: half the speed
  Advance(1ms);
  EXPECT_EQ(Read(0x7100, 1, true), 3000);
  EXPECT_EQ(TryWrite(0x3413, 0, 0, 4), SdoAborted(0x3413, 0, 0x06090032));
}

// Design decision 10: a moving count keeps the device ticking only while something consumes it
// (here output 1's control source, 2340h = 2) or filters it (61A0h); it sleeps once it stops.
TEST_F(QuadratureDeviceTest, AMovingCountTicksOnlyWhileConsumed) {
  SetNumber("ENC.speed_rpm", 600);
  Advance(5ms);
  EXPECT_FALSE(device().Ticking());
  Write(0x2340, 1, 2, 1);
  Advance(5ms);
  EXPECT_TRUE(device().Ticking());
  const auto before = device().Evaluations();
  Advance(100ms);
  EXPECT_EQ(device().Evaluations() - before, 100u);
  SetNumber("ENC.speed_rpm", 0);
  Advance(2100ms);  // the output ramps down, then all is steady
  EXPECT_FALSE(device().Ticking());
}

}  // namespace
}  // namespace canfleet::devices::encoder::test
