// Idle is free (issue 20 §1, design decision 10): a Quad with steady inputs sleeps until its next
// protocol deadline (heartbeat, TPDO event timer), and what wakes it (an input, an NMT command, a
// fault delay, a lost heartbeat) takes effect at exactly the instant a fixed 10 ms / 1 ms tick would
// have given (AX020506 §2.3 "sampled every 10ms", §3.5.8 ramps, §4.2 fault delays and reactions).
#include "tests/unit/devices/quad_fixture.hpp"

namespace canfleet::devices::test {
namespace {

class QuadIdleTest : public QuadTest {
 protected:
  /// Advances to `t` after power-on (simulated time starts at 0).
  void AdvanceTo(Duration t) { scheduler_.AdvanceTo(TimePoint{t}); }
  double Current(int n) { return io().Number("OUT" + std::to_string(n) + ".current_mA"); }
  /// POUT1 ← AIN1 through the default profile: 2500 mV gives 750 mA, ramped at 1 mA/ms (3080h
  /// 1500 ms for 0 → 1500 mA, the profile's highest current); settled well before 1 s.
  void DriveOutput1FromInput1() {
    Write(0x3010, 1, 1, 1);
    AdvanceTo(1s);
    ASSERT_EQ(Current(1), 750);
  }
};

// CiA 301 §7.2.8.3.2.2: the heartbeat producer is the only wake-up of an idle pre-operational node
// (no TPDOs there): 20 timers in 10 s, each one a heartbeat on the bus. With fixed ticks the clock
// fired 11 000 times (10 000 output ticks, 1 000 samples).
TEST_F(QuadIdleTest, AnIdlePreOperationalQuadWakesOnlyForItsHeartbeat) {
  Write(0x1017, 0, 500, 2);
  AdvanceTo(1s);
  Frames();
  const std::uint64_t fired = scheduler_.FiredCount();
  AdvanceTo(11s);
  EXPECT_EQ(scheduler_.FiredCount() - fired, 20u);
  EXPECT_EQ(Frames("705#").size(), 20u);
  EXPECT_EQ(scheduler_.SleepingCount(), 2u);  // the 10 ms sample and the 1 ms output stage
}

// Operational at defaults (§3.1.1: TPDO1-4 type 254 with a 100 ms event timer): every wake-up of
// the node puts a frame on the bus, 4 TPDOs × 100 + 20 heartbeats in 10 s.
TEST_F(QuadIdleTest, AnIdleOperationalQuadWakesOnlyForItsTpdoTimersAndHeartbeat) {
  Write(0x1017, 0, 500, 2);
  Start();
  AdvanceTo(1s);
  Frames();
  const std::uint64_t fired = scheduler_.FiredCount();
  AdvanceTo(11s);
  const auto frames = Frames();
  EXPECT_EQ(scheduler_.FiredCount() - fired, 420u);
  EXPECT_EQ(frames.size(), 420u);
  // Nothing is armed earlier than the next TPDO event timers (started by the NMT start at 0).
  EXPECT_EQ(scheduler_.NextDeadline(), TimePoint{11s + 100ms});
}

// §2.3, §3.5.8: an input set between two samples is seen at the next 10 ms sample, and the output
// ramps from that instant at 1 mA per 1 ms tick: 750 → 1500 mA ends 750 ticks after the sample.
TEST_F(QuadIdleTest, AnInputSetWhileAsleepIsSampledAndRampedOnTheFixedGrid) {
  DriveOutput1FromInput1();
  AdvanceTo(5s + 3500us);
  SetNumber("IN1.voltage_mV", 4500);  // target 1500 mA
  AdvanceTo(5010ms - 1ns);
  EXPECT_EQ(od().GetUnsigned(0x7100, 1), 2500u);
  EXPECT_EQ(Current(1), 750);
  AdvanceTo(5010ms);  // the sample, then the output tick of the same instant
  EXPECT_EQ(od().GetUnsigned(0x7100, 1), 4500u);
  EXPECT_EQ(Current(1), 751);
  AdvanceTo(5759ms - 1ns);
  EXPECT_EQ(Current(1), 1499);
  AdvanceTo(5759ms);
  EXPECT_EQ(Current(1), 1500);
  AdvanceTo(6s);
  EXPECT_EQ(Current(1), 1500);
}

// §4.2: a fault seen at a sample becomes active after its 20B0h delay, to the nanosecond, and the
// controller fault state (6340h = 1: 7341h = 0 mA) takes the outputs at that same instant.
TEST_F(QuadIdleTest, AFaultDelayEndsAndItsReactionHappensAtTheSameInstant) {
  DriveOutput1FromInput1();
  Write(0x20B0, 2, 1000, 2);
  Write(0x20A0, 1, 0x02, 1);  // error checking on AIN2
  AdvanceTo(5s + 3500us);
  SetNumber("IN2.voltage_mV", 100);  // below 2010h = 200 mV: pending at the 5.010 s sample
  AdvanceTo(6010ms - 1ns);
  EXPECT_TRUE(Frames("085#").empty());
  EXPECT_EQ(Current(1), 750);
  AdvanceTo(6010ms);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{Emcy(0xFF00, 0x01, 2, 0x01)});
  EXPECT_EQ(Current(1), 0);
}

// CiA 301 §7.2.8.3.2.2, AX020506 §4.2: a lost heartbeat (1016h) is an active error; the output
// stage sees the fault state at its next 1 ms tick after the loss.
TEST_F(QuadIdleTest, AHeartbeatLostWhileAsleepTakesTheOutputsAtTheNextOutputTick) {
  DriveOutput1FromInput1();
  Write(0x1016, 1, 0x000100C8, 4);  // node 1, 200 ms
  AdvanceTo(5s + 3500us);
  Send("701#05");  // node 1 is operational: the consumer starts
  AdvanceTo(5204ms - 1ns);
  EXPECT_EQ(Current(1), 750);
  EXPECT_EQ(Frames("085#").size(), 1u);  // 8130h at 5.2035 s
  AdvanceTo(5204ms);
  EXPECT_EQ(Current(1), 0);
}

// §4.2 "Pre-Operational Behaviour": a CAN-controlled output is off outside operational; the NMT
// start wakes the output stage, which drives it again at its next 1 ms tick.
TEST_F(QuadIdleTest, AnNmtStartWhileAsleepDrivesCanOutputsAtTheNextOutputTick) {
  Start();
  Write(0x7330, 2, 1000, 2);  // POUT2 under CAN control (3010h = 0), 30A0h = 2: no ramp
  AdvanceTo(1s);
  EXPECT_EQ(Current(2), 1000);
  Send("000#8005");  // enter pre-operational: off at the next output tick
  AdvanceTo(1001ms);
  EXPECT_EQ(Current(2), 0);
  AdvanceTo(5s + 3500us);
  Send("000#0105");
  AdvanceTo(5004ms - 1ns);
  EXPECT_EQ(Current(2), 0);
  AdvanceTo(5004ms);
  EXPECT_EQ(Current(2), 1000);
}

}  // namespace
}  // namespace canfleet::devices::test
