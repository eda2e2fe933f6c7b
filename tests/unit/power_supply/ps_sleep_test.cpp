// Sleep mode of the PS-24-24-350W-CAN (UMAX080311 §1.2.2, 2311h): after 2311h ms commanded OFF the
// controller sleeps (its port is muted: no heartbeat, no answer); any CAN frame or an Enable change
// wakes it; never in Operational.
#include "tests/unit/power_supply/ps_fixture.hpp"

namespace canfleet::devices::test {
namespace {

class PsSleepTest : public PsTest {
 protected:
  bool Asleep() { return io().Bool("PS.asleep"); }
  /// 1017h = 100 ms: the heartbeats show whether the node speaks.
  std::size_t Heartbeats(Duration span) {
    Frames();
    Advance(span);
    return Frames("77F#").size();
  }
};

// §1.2.2: "If object 2311h PS Sleep Delay is set to 0, sleep mode is disabled."
TEST_F(PsSleepTest, DisabledByDefault) {
  Write(0x1017, 0, 100, 2);
  Advance(10s);
  EXPECT_FALSE(Asleep());
  EXPECT_EQ(Heartbeats(1s), 10u);
}

// §1.2.2: "the controller will wait the amount of time (in milliseconds) specified in object 2311h
// PS Sleep Delay before going to sleep. The controller will wake upon receiving a CAN frame".
// The waking frame is served (README choice 12).
TEST_F(PsSleepTest, SleepsAfter2311hAndAnyFrameWakesIt) {
  Write(0x1017, 0, 100, 2);
  Write(0x2311, 0, 500, 2);  // seen by the loop 1 ms later: the delay starts then
  Advance(500ms);
  EXPECT_FALSE(Asleep());
  Advance(1ms);
  EXPECT_TRUE(Asleep());
  EXPECT_EQ(Heartbeats(2s), 0u);
  EXPECT_FALSE(ps().LoopRunning());
  // Any frame, even one for another node, wakes it; an SDO request is answered.
  Send("123#00");
  EXPECT_FALSE(Asleep());
  EXPECT_GE(Heartbeats(400ms), 3u);
  Advance(101ms);  // 500 ms after the loop saw the wake: asleep again
  EXPECT_TRUE(Asleep());
  EXPECT_EQ(Read(0x2311, 0), 500);
  EXPECT_FALSE(Asleep());
}

// §1.2.2: "... or when the Remote Enable signal changes state". High also switches the output on:
// not commanded off, so no sleep.
TEST_F(PsSleepTest, TheEnablePinWakesIt) {
  Write(0x2311, 0, 200, 2);
  Advance(300ms);
  ASSERT_TRUE(Asleep());
  SetNumber("VIN.voltage_mV", 20000);  // another input does not wake it
  Advance(10ms);
  EXPECT_TRUE(Asleep());
  Enable(true);
  EXPECT_FALSE(Asleep());
  Advance(1ms);
  EXPECT_TRUE(io().Bool("PS.output_on"));
  Advance(1s);
  EXPECT_FALSE(Asleep());
}

// §1.2.2: "If the device NMT state is in Operational Mode the device will not go to sleep, to
// continue sending and receiving PDOs"; back in pre-operational the delay starts again.
TEST_F(PsSleepTest, NeverInOperational) {
  Write(0x2311, 0, 200, 2);
  Start();
  Advance(2s);
  EXPECT_FALSE(Asleep());
  Send("000#807F");  // enter pre-operational; the loop sees it 1 ms later
  Advance(200ms);
  EXPECT_FALSE(Asleep());
  Advance(1ms);
  EXPECT_TRUE(Asleep());
}

// "if during regular operation the power supply is commanded OFF": with the output on, no sleep;
// once commanded off (and any shutdown countdown over) the delay runs.
TEST_F(PsSleepTest, OnlyWhileCommandedOff) {
  Write(0x2311, 0, 200, 2);
  Write(0x2302, 0, 300, 4);
  OnByCan();
  Advance(1s);
  EXPECT_FALSE(Asleep());
  Write(0x6200, 2, 0xFC, 1);
  Advance(300ms);  // countdown
  EXPECT_FALSE(Asleep());
  Advance(1ms);
  ASSERT_FALSE(io().Bool("PS.output_on"));
  Advance(199ms);
  EXPECT_FALSE(Asleep());
  Advance(1ms);
  EXPECT_TRUE(Asleep());
}

}  // namespace
}  // namespace canfleet::devices::test
