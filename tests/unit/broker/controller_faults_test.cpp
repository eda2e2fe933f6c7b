// Direct controller faults for the fleet manager (FaultStage): bus-off held until recovered on
// command, a controller held error-passive, and the babbling idiot. Counting rules of
// ISO 11898-1:2015 §12.1.4 (bus/physics/fault_confinement.hpp); recovery after 128 × 11 recessive bits
// (§12.1.4.2) unless held.
#include <gtest/gtest.h>

#include <stdexcept>

#include "bus/physics/wire_model.hpp"
#include "orchestrator/broker/broker.hpp"
#include "tests/unit/broker/broker_test_support.hpp"

namespace canfleet::broker {
namespace {

using namespace test;
constexpr std::uint32_t kRate = 500'000;  // 2 µs per bit

BusTime Bits(std::uint64_t n) {
  return BitTime(n, kRate);
}

class ControllerFaults : public ::testing::Test {
 protected:
  SimulatedScheduler s;
  Broker broker{s};
  bool bus_added = (broker.AddBus({.name = "can0", .bitrate = kRate}), true);
  RecordingSink a{&s}, b{&s}, c{&s};
  PortId pa = broker.Attach("can0", "a", a);
  PortId pb = broker.Attach("can0", "b", b);
  FaultStage& faults = broker.Faults("can0");
};

// ---- bus-off held until commanded ---------------------------------------------------------------

// Given a bus that recovers by itself, when a port is forced bus-off with hold, then it is still
// bus-off long after 1408 bit times, and only RecoverBusOff brings it back; the hold ends there,
// so a later bus-off without hold recovers by itself again.
TEST_F(ControllerFaults, AHeldBusOffWaitsForRecoverBusOff) {
  s.Advance(1ms);
  EXPECT_TRUE(faults.ForceBusOff(pa, /*hold=*/true));
  EXPECT_FALSE(faults.ForceBusOff(pa, true));  // already bus-off and held
  EXPECT_FALSE(faults.ForceBusOff(pa));        // already bus-off
  s.Advance(10s);
  EXPECT_EQ(a.States(), (std::vector<ControllerState>{ControllerState::kBusOff}));
  EXPECT_EQ(broker.Submit(pa, Frame("181#01")), 0u);

  EXPECT_TRUE(broker.RecoverBusOff(pa));
  ASSERT_EQ(a.events.size(), 2u);
  EXPECT_EQ(a.events[1].state, ControllerState::kErrorActive);
  EXPECT_EQ(a.events[1].tec, 0);
  EXPECT_EQ(a.event_times[1], 1ms + 10s);
  broker.Submit(pa, Frame("181#02"));
  s.Advance(1ms);
  EXPECT_EQ(b.Ids(), (std::vector<std::string>{"181#02"}));

  EXPECT_TRUE(faults.ForceBusOff(pa));  // no hold: the default behaviour
  const BusTime off_at = s.Now().time_since_epoch();
  s.Advance(Bits(kBusOffRecoveryBits));
  ASSERT_EQ(a.events.size(), 4u);
  EXPECT_EQ(a.events[3].state, ControllerState::kErrorActive);
  EXPECT_EQ(a.event_times[3], off_at + Bits(kBusOffRecoveryBits));
}

// Given a port already bus-off and waiting for its automatic recovery, holding it cancels that
// recovery (the fleet manager may hold a port that went bus-off by itself).
TEST_F(ControllerFaults, HoldingABusOffPortCancelsItsAutomaticRecovery) {
  EXPECT_TRUE(faults.ForceBusOff(pa));
  s.Advance(Bits(kBusOffRecoveryBits) / 2);
  EXPECT_TRUE(faults.ForceBusOff(pa, true));
  s.Advance(1s);
  EXPECT_EQ(broker.Port(pa).controller.state, ControllerState::kBusOff);
  EXPECT_EQ(a.events.size(), 1u);
  EXPECT_TRUE(broker.RecoverBusOff(pa));
  EXPECT_EQ(broker.Port(pa).controller.state, ControllerState::kErrorActive);
}

// Given a port driven bus-off by errors (32 corrupted attempts), holding it then keeps it off
// past its automatic recovery; RecoverBusOff ends it.
TEST_F(ControllerFaults, ABusOffReachedThroughErrorsCanBeHeld) {
  faults.Add({.source = pa, .action = RuleAction::kCorrupt, .count = 32});
  broker.Submit(pa, Frame("181#01"));
  const std::uint32_t c_bits = StuffedBits("181#01") + kCrcErrorTailBits;
  const BusTime bus_off_at = Bits(32 * c_bits + 16 * kSuspendTransmissionBits);
  s.AdvanceTo(T(bus_off_at));
  ASSERT_EQ(broker.Port(pa).controller.state, ControllerState::kBusOff);
  EXPECT_TRUE(faults.ForceBusOff(pa, true));
  ASSERT_EQ(a.events.size(), 2u);  // error-passive, bus-off: holding adds no event
  s.Advance(1s);
  EXPECT_EQ(broker.Port(pa).controller.state, ControllerState::kBusOff);
  EXPECT_TRUE(broker.RecoverBusOff(pa));
  EXPECT_EQ(a.events.back().state, ControllerState::kErrorActive);
}

// ---- bus-off with a cause that persists ----------------------------------------------------------

// Given a bus that recovers by itself, when a cause holds a port bus-off (HoldBusOff), then every
// automatic recovery attempt (1408 bit times after the bus-off, then every 1408 bit times,
// ISO 11898-1:2015 §12.1.4.2) fails and is counted, recovery on command fails too, the port stays
// bus-off with TEC 256 and sends nothing throughout; when the cause ends, the next attempt
// succeeds (error-active, TEC 0) and its frames flow again.
TEST_F(ControllerFaults, ABusOffHeldByACauseFailsEveryRecoveryAttemptUntilReleased) {
  s.Advance(1ms);
  const BusTime off_at = s.Now().time_since_epoch();
  const BusTime period = Bits(kBusOffRecoveryBits);  // 2.816 ms at 500 kbit/s
  EXPECT_TRUE(faults.HoldBusOff(pa, true));
  EXPECT_FALSE(faults.HoldBusOff(pa, true));  // already held
  ASSERT_EQ(a.events.size(), 1u);
  EXPECT_EQ(a.events[0].state, ControllerState::kBusOff);
  EXPECT_EQ(a.events[0].tec, 256);

  // Just before the third attempt: two have failed; state and counters are visible all along.
  s.AdvanceTo(T(off_at + 3 * period - 1ns));
  PortStats held = broker.Port(pa);
  EXPECT_EQ(held.controller.state, ControllerState::kBusOff);
  EXPECT_EQ(held.controller.tec, 256);
  EXPECT_EQ(held.failed_recoveries, 2u);
  EXPECT_EQ(a.events.size(), 1u) << "a failed attempt changes nothing the node could see";
  EXPECT_EQ(broker.Submit(pa, Frame("181#01")), 0u);
  EXPECT_FALSE(broker.RecoverBusOff(pa)) << "recovery on command fails while the cause lasts";
  EXPECT_EQ(broker.Port(pa).failed_recoveries, 3u);
  s.AdvanceTo(T(off_at + 3 * period));
  EXPECT_EQ(broker.Port(pa).failed_recoveries, 4u);
  EXPECT_EQ(broker.Port(pa).controller.state, ControllerState::kBusOff);

  // The cause ends between two attempts: the next one, at 4 periods, succeeds.
  s.Advance(period / 2);
  EXPECT_TRUE(faults.HoldBusOff(pa, false));
  EXPECT_FALSE(faults.HoldBusOff(pa, false));
  EXPECT_EQ(broker.Port(pa).controller.state, ControllerState::kBusOff);
  s.AdvanceTo(T(off_at + 4 * period));
  ASSERT_EQ(a.events.size(), 2u);
  EXPECT_EQ(a.events[1].state, ControllerState::kErrorActive);
  EXPECT_EQ(a.events[1].tec, 0);
  EXPECT_EQ(a.event_times[1], off_at + 4 * period);
  EXPECT_EQ(broker.Port(pa).failed_recoveries, 4u);
  broker.Submit(pa, Frame("181#02"));
  s.Advance(1ms);
  EXPECT_EQ(b.Ids(), (std::vector<std::string>{"181#02"}));
}

// Given a bus that recovers only on command, a port held by a cause is bus-off and makes no
// attempts of its own; RecoverBusOff fails while the cause lasts and succeeds once it ended.
TEST_F(ControllerFaults, OnABusWithoutAutomaticRecoveryOnlyTheCommandAttemptsIt) {
  broker.AddBus({.name = "manual", .bitrate = kRate, .auto_recover = false});
  RecordingSink m1{&s}, m2{&s};
  const PortId p1 = broker.Attach("manual", "m1", m1);
  broker.Attach("manual", "m2", m2);
  FaultStage& manual = broker.Faults("manual");
  EXPECT_TRUE(manual.HoldBusOff(p1, true));
  s.Advance(1s);
  EXPECT_EQ(broker.Port(p1).failed_recoveries, 0u);
  EXPECT_FALSE(broker.RecoverBusOff(p1));
  EXPECT_EQ(broker.Port(p1).failed_recoveries, 1u);
  EXPECT_TRUE(manual.HoldBusOff(p1, false));
  s.Advance(1s);
  EXPECT_EQ(broker.Port(p1).controller.state, ControllerState::kBusOff);
  EXPECT_TRUE(broker.RecoverBusOff(p1));
  EXPECT_EQ(m1.States(),
            (std::vector<ControllerState>{ControllerState::kBusOff, ControllerState::kErrorActive}));
}

// Given a port already bus-off through errors, a cause added then makes its pending automatic
// attempt fail (no second bus-off event).
TEST_F(ControllerFaults, ACauseAddedToABusOffPortMakesItsPendingAttemptFail) {
  EXPECT_TRUE(faults.ForceBusOff(pa));
  const BusTime off_at = s.Now().time_since_epoch();
  EXPECT_TRUE(faults.HoldBusOff(pa, true));
  EXPECT_EQ(a.events.size(), 1u);
  s.AdvanceTo(T(off_at + Bits(kBusOffRecoveryBits)));
  EXPECT_EQ(broker.Port(pa).controller.state, ControllerState::kBusOff);
  EXPECT_EQ(broker.Port(pa).failed_recoveries, 1u);
}

// ---- error-passive held ---------------------------------------------------------------------

// Given the hold, then the port is error-passive at once (TEC 128, an event to the node);
// successful transmissions do not bring it back; released, TEC is 127 and it is error-active
// again (with an event); the next success counts down from there.
TEST_F(ControllerFaults, HeldErrorPassiveUntilReleased) {
  s.Advance(2ms);
  EXPECT_TRUE(faults.HoldErrorPassive(pa, true));
  EXPECT_FALSE(faults.HoldErrorPassive(pa, true));
  ASSERT_EQ(a.events.size(), 1u);
  EXPECT_EQ(a.events[0].state, ControllerState::kErrorPassive);
  EXPECT_EQ(a.events[0].tec, 128);
  EXPECT_EQ(a.event_times[0], 2ms);
  EXPECT_TRUE(b.events.empty());

  for (int i = 0; i < 200; ++i)
    broker.Submit(pa, Frame("181#01"));
  s.Advance(1s);
  EXPECT_EQ(b.frames.size(), 200u);
  EXPECT_EQ(a.events.size(), 1u);
  EXPECT_EQ(broker.Port(pa).controller.state, ControllerState::kErrorPassive);
  EXPECT_EQ(broker.Port(pa).controller.tec, 128);

  EXPECT_TRUE(faults.HoldErrorPassive(pa, false));
  EXPECT_FALSE(faults.HoldErrorPassive(pa, false));
  ASSERT_EQ(a.events.size(), 2u);
  EXPECT_EQ(a.events[1].state, ControllerState::kErrorActive);
  EXPECT_EQ(a.events[1].tec, 127);
  broker.Submit(pa, Frame("181#02"));
  s.Advance(1ms);
  EXPECT_EQ(broker.Port(pa).controller.tec, 126);
}

// While held, errors still count (rule 3: TEC + 8): 16 corrupted attempts take TEC from 128 to
// 256 > 255, bus-off. The automatic recovery keeps the hold: error-passive with TEC 128.
TEST_F(ControllerFaults, AHeldPortStillGoesBusOffAndRecoversErrorPassive) {
  faults.HoldErrorPassive(pa, true);
  faults.Add({.source = pa, .action = RuleAction::kCorrupt, .count = 16});
  broker.Submit(pa, Frame("181#01"));
  const std::uint32_t c_bits = StuffedBits("181#01") + kCrcErrorTailBits;
  // Error-passive throughout: 8 bits of suspend transmission after each attempt.
  const BusTime bus_off_at = Bits(16 * c_bits + 15 * kSuspendTransmissionBits);
  s.AdvanceTo(T(bus_off_at));
  ASSERT_EQ(a.events.size(), 2u);
  EXPECT_EQ(a.events[1].state, ControllerState::kBusOff);
  EXPECT_EQ(a.events[1].tec, 256);
  EXPECT_EQ(a.event_times[1], bus_off_at);
  s.Advance(Bits(kBusOffRecoveryBits));
  ASSERT_EQ(a.events.size(), 3u);
  EXPECT_EQ(a.events[2].state, ControllerState::kErrorPassive);
  EXPECT_EQ(a.events[2].tec, 128);
  EXPECT_EQ(a.events[2].rec, 0);
}

// Released after errors raised TEC above 128, TEC still goes back to 127 (the fault is gone).
TEST_F(ControllerFaults, ReleasingTheHoldCapsTecAt127) {
  faults.HoldErrorPassive(pa, true);
  faults.Add({.source = pa, .action = RuleAction::kCorrupt, .count = 9});
  broker.Submit(pa, Frame("181#01"));
  s.Advance(10ms);
  ASSERT_EQ(broker.Port(pa).controller.tec, 128 + 9 * 8 - 1);  // 9 errors, then the success
  faults.HoldErrorPassive(pa, false);
  EXPECT_EQ(broker.Port(pa).controller.tec, 127);
  EXPECT_EQ(a.events.back().state, ControllerState::kErrorActive);
}

TEST_F(ControllerFaults, ControllerFaultsOnAPortOfAnotherBusAreRefused) {
  broker.AddBus({.name = "can1"});
  const PortId other = broker.Attach("can1", "x", c);
  EXPECT_THROW(faults.ForceBusOff(other, true), std::invalid_argument);
  EXPECT_THROW(faults.HoldBusOff(other, true), std::invalid_argument);
  EXPECT_THROW(faults.HoldErrorPassive(other, true), std::invalid_argument);
  EXPECT_THROW(faults.StartBabbling(other, Frame("001#")), std::invalid_argument);
  EXPECT_THROW(faults.StopBabbling(other), std::invalid_argument);
}

// ---- babbling idiot -------------------------------------------------------------------------

// Given a babbles 001h, then the bus carries 001h back to back (each frame's exact duration, no
// gap), c's 100h never wins an arbitration and a's own frame waits behind the babble; a's node
// gets no confirmation for the babble. After StopBabbling the frame on the wire completes, then
// c's and a's frames go in arbitration order.
TEST_F(ControllerFaults, ABabblingIdiotFloodsTheBusAtItsFullRate) {
  const PortId pc = broker.Attach("can0", "c", c);
  s.Advance(1ms);
  const CanFrame babble = Frame("001#0011223344556677");
  EXPECT_TRUE(faults.StartBabbling(pa, babble));
  broker.Submit(pc, Frame("100#01"));
  broker.Submit(pa, Frame("181#01"));
  s.Advance(10ms);

  const BusTime f = FrameTime("001#0011223344556677", kRate);
  const auto n = static_cast<std::size_t>(BusTime(10ms) / f);
  ASSERT_EQ(b.frames.size(), n);
  for (std::size_t i = 0; i < n; ++i)
    ASSERT_EQ(At(b.frames[i]), At("001#0011223344556677", 1ms + f * static_cast<std::int64_t>(i + 1)));
  EXPECT_EQ(c.frames.size(), n);
  EXPECT_TRUE(a.confirmed.empty());
  EXPECT_TRUE(c.confirmed.empty());
  PortStats stats = broker.Port(pa);
  EXPECT_EQ(stats.babble_frames, n);
  EXPECT_EQ(stats.tx_frames, 0u);
  EXPECT_EQ(stats.queued, 1u);
  EXPECT_EQ(broker.Port(pc).queued, 1u);
  EXPECT_EQ(broker.Stats("can0").frames, n);

  EXPECT_TRUE(faults.StopBabbling(pa));
  EXPECT_FALSE(faults.StopBabbling(pa));
  s.Advance(10ms);
  const BusTime last_babble_end = 1ms + f * static_cast<std::int64_t>(n + 1);  // was on the wire
  const BusTime e1 = last_babble_end + FrameTime("100#01", kRate);
  const BusTime e2 = e1 + FrameTime("181#01", kRate);
  ASSERT_EQ(b.frames.size(), n + 3);
  EXPECT_EQ(At(b.frames[n]), At("001#0011223344556677", last_babble_end));
  EXPECT_EQ(At(b.frames[n + 1]), At("100#01", e1));
  EXPECT_EQ(At(b.frames[n + 2]), At("181#01", e2));
  EXPECT_EQ(a.Confirmed(), (std::vector<std::string>{At("181#01", e2)}));
  EXPECT_EQ(broker.Port(pa).babble_frames, n + 1);
}

// A babble frame with a lower priority than someone else's loses arbitration like any frame.
TEST_F(ControllerFaults, ABabbleFrameStillLosesToALowerIdentifier) {
  faults.StartBabbling(pa, Frame("700#"));
  broker.Submit(pb, Frame("080#01"));
  s.Advance(1ms);
  ASSERT_GE(a.frames.size(), 1u);
  EXPECT_EQ(ToCandump(a.frames[0].frame), "080#01");
  EXPECT_GT(b.frames.size(), 2u);
}

TEST(ControllerFaultsUnpaced, BabblingNeedsAPacedBus) {
  SimulatedScheduler s;
  Broker broker(s);
  broker.AddBus({.name = "fast", .paced = false});
  RecordingSink a;
  const PortId pa = broker.Attach("fast", "a", a);
  EXPECT_THROW(broker.Faults("fast").StartBabbling(pa, Frame("001#")), std::invalid_argument);
}

// ---- unpaced order (the O(1) oldest head) -----------------------------------------------------

// FIFO across ports survives frames leaving queues without being sent: a's queue is dropped at
// bus-off, d detaches with frames queued; the remaining frames still go in submission order.
TEST(ControllerFaultsUnpaced, SubmissionOrderSurvivesBusOffAndDetach) {
  SimulatedScheduler s;
  Broker broker(s);
  broker.AddBus({.name = "fast", .paced = false});
  RecordingSink a, b, c, d;
  const PortId pa = broker.Attach("fast", "a", a);
  const PortId pb = broker.Attach("fast", "b", b);
  broker.Attach("fast", "c", c);
  const PortId pd = broker.Attach("fast", "d", d);
  broker.Submit(pa, Frame("1A1#"));
  broker.Submit(pd, Frame("1D1#"));
  broker.Submit(pb, Frame("1B1#"));
  broker.Submit(pa, Frame("1A2#"));
  broker.Submit(pd, Frame("1D2#"));
  broker.Faults("fast").ForceBusOff(pa, true);
  broker.Detach(pd);
  broker.RecoverBusOff(pa);
  broker.Submit(pa, Frame("1A3#"));
  broker.Submit(pb, Frame("1B2#"));
  s.Advance(1ns);
  EXPECT_EQ(c.Ids(), (std::vector<std::string>{"1B1#", "1A3#", "1B2#"}));
}

// A lone unpaced port that got an ACK error waits for an acknowledger; a port that recovers from
// bus-off is one (before, only an attaching port released the wait).
TEST(ControllerFaultsUnpaced, APortRecoveringFromBusOffAcknowledgesAWaitingPort) {
  SimulatedScheduler s;
  Broker broker(s);
  broker.AddBus({.name = "fast", .paced = false});
  RecordingSink a, b;
  const PortId pa = broker.Attach("fast", "a", a);
  const PortId pb = broker.Attach("fast", "b", b);
  broker.Faults("fast").ForceBusOff(pb, true);
  broker.Submit(pa, Frame("181#01"));
  s.Advance(1ms);
  EXPECT_EQ(broker.Port(pa).tx_errors, 1u);
  EXPECT_TRUE(b.frames.empty());
  broker.RecoverBusOff(pb);
  s.Advance(1ms);
  EXPECT_EQ(b.Ids(), (std::vector<std::string>{"181#01"}));
  EXPECT_EQ(broker.Port(pa).tx_errors, 1u);
}

}  // namespace
}  // namespace canfleet::broker
