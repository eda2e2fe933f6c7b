// Error confinement on the broker's ports, ISO 11898-1:2015 §12.1.4 (the counting rules, via
// bus/physics/fault_confinement.hpp), §6.10 ACK, §6.11 automatic retransmission, §6.14 error-passive
// (suspend transmission), §6.15 bus-off, §12.1.4.2 bus-off recovery after 128 × 11 recessive bits.
#include <gtest/gtest.h>

#include <algorithm>

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

class Confinement : public ::testing::Test {
 protected:
  Confinement() { broker.AddBus({.name = "can0", .bitrate = kRate}); }
  PortId Add(RecordingSink& sink, AttachOptions options = {}) {
    return broker.Attach("can0", "port", sink, options);
  }

  SimulatedScheduler s;
  Broker broker{s};
  RecordingSink a{&s}, b{&s}, c{&s};
};

// Given a port alone on the bus, when it sends, then nobody acknowledges: each attempt is the
// frame up to the ACK slot plus an error frame (stuffed bits + 19), TEC + 8 per attempt; after 16
// it is error-passive (TEC 128), ACK errors stop counting, and it retransmits forever (with 8 bits
// of suspend transmission between attempts) without ever going bus-off.
TEST_F(Confinement, ALonePortGoesErrorPassiveThroughAckErrorsAndNeverBusOff) {
  const PortId pa = Add(a);
  broker.Submit(pa, Frame("701#05"));
  const std::uint32_t attempt = StuffedBits("701#05") + kAckErrorTailBits;
  ASSERT_EQ(attempt, 45u + 19u);  // 42 bits + 3 stuff bits, worked in the frame-timing tests

  const BusTime t16 = Bits(16 * attempt);
  s.AdvanceTo(T(t16 - 1ns));
  EXPECT_TRUE(a.events.empty());
  EXPECT_EQ(broker.Port(pa).controller.tec, 120);
  s.AdvanceTo(T(t16));
  ASSERT_EQ(a.events.size(), 1u);
  EXPECT_EQ(a.events[0].state, ControllerState::kErrorPassive);
  EXPECT_EQ(a.events[0].tec, 128);
  EXPECT_EQ(a.event_times[0], t16);

  s.Advance(1s);
  const PortStats port = broker.Port(pa);
  EXPECT_EQ(a.events.size(), 1u);
  EXPECT_EQ(port.controller.state, ControllerState::kErrorPassive);
  EXPECT_EQ(port.controller.tec, 128);
  EXPECT_EQ(port.queued, 1u);  // still trying
  EXPECT_EQ(port.tx_frames, 0u);
  EXPECT_TRUE(a.confirmed.empty());
  const BusTime period = Bits(attempt + kSuspendTransmissionBits);
  const std::int64_t after_passive = BusTime(1s).count() / period.count();
  EXPECT_EQ(port.tx_errors, static_cast<std::uint64_t>(16 + after_passive));
  EXPECT_EQ(broker.Stats("can0").error_frames, port.tx_errors);
  EXPECT_EQ(broker.Stats("can0").frames, 0u);

  // Given a second port attaching now, when the attempt on the wire (started before it attached)
  // has failed, then the next one is acknowledged: delivered, confirmed, TEC 127 → error-active.
  ASSERT_LE(period * after_passive + Bits(kSuspendTransmissionBits), 1s);  // an attempt is on the wire
  const PortId pb = Add(b);
  s.Advance(10ms);
  const BusTime failing_end = t16 + period * (after_passive + 1);
  const BusTime success_end = failing_end + Bits(kSuspendTransmissionBits) + FrameTime("701#05", kRate);
  EXPECT_EQ(b.Received(), (std::vector<std::string>{At("701#05", success_end)}));
  EXPECT_EQ(a.Confirmed(), b.Received());
  ASSERT_EQ(a.events.size(), 2u);
  EXPECT_EQ(a.events[1].state, ControllerState::kErrorActive);
  EXPECT_EQ(a.events[1].tec, 127);
  EXPECT_EQ(broker.Port(pb).controller.rec, 0);
}

// A listen-only port (a capture tool) does not acknowledge: the lone node still gets ACK errors.
// With error frames enabled, the monitor sees each failed attempt as an error frame.
TEST_F(Confinement, AListenOnlyPortDoesNotAcknowledge) {
  const PortId pa = Add(a);
  const PortId pm = Add(b, {.listen_only = true, .error_frames = true});
  broker.Submit(pa, Frame("701#05"));
  const std::uint32_t attempt = StuffedBits("701#05") + kAckErrorTailBits;
  s.AdvanceTo(T(Bits(2 * attempt)));
  EXPECT_EQ(b.Received(), (std::vector<std::string>{"701#!@" + std::to_string(Bits(attempt).count()),
                                                    "701#!@" + std::to_string(Bits(2 * attempt).count())}));
  EXPECT_EQ(broker.Submit(pm, Frame("123#")), 0u);  // a monitor does not transmit
  EXPECT_EQ(broker.Port(pm).invalid_drops, 1u);
  EXPECT_EQ(broker.Port(pm).controller.rec, 0);
}

// Given a corrupt rule on a's frames, then every attempt is destroyed by an error frame (stuffed
// bits + 20): a's TEC + 8 each time, b's REC + 1. Attempts 1-16 error-active, back to back;
// 17-32 error-passive, each after 8 bits of suspend transmission. The 32nd makes TEC 256 > 255:
// bus-off at 32 c + 128 bits; a's queue is dropped. 1408 bit times later a recovers by itself.
TEST_F(Confinement, ACorruptRuleDrivesThePortBusOffAfter32AttemptsAndItRecoversAfter1408Bits) {
  const PortId pa = Add(a);
  const PortId pb = Add(b);
  broker.Faults("can0").Add({.source = pa, .action = RuleAction::kCorrupt});
  const CanFrame frames[] = {Frame("181#01"), Frame("181#02")};
  broker.Submit(pa, frames);
  const std::uint32_t c_bits = StuffedBits("181#01") + kCrcErrorTailBits;
  const BusTime passive_at = Bits(16 * c_bits);
  const BusTime bus_off_at = Bits(32 * c_bits + 16 * kSuspendTransmissionBits);

  s.AdvanceTo(T(bus_off_at - 1ns));
  EXPECT_EQ(broker.Port(pa).controller.tec, 248);
  s.AdvanceTo(T(bus_off_at));
  ASSERT_EQ(a.events.size(), 2u);
  EXPECT_EQ(a.events[0].state, ControllerState::kErrorPassive);
  EXPECT_EQ(a.events[0].tec, 128);
  EXPECT_EQ(a.event_times[0], passive_at);
  EXPECT_EQ(a.events[1].state, ControllerState::kBusOff);
  EXPECT_EQ(a.events[1].tec, 256);
  EXPECT_EQ(a.event_times[1], bus_off_at);

  PortStats pa_stats = broker.Port(pa);
  EXPECT_EQ(pa_stats.tx_errors, 32u);
  EXPECT_EQ(pa_stats.queued, 0u);
  EXPECT_EQ(pa_stats.bus_off_drops, 2u);
  EXPECT_TRUE(a.confirmed.empty());
  EXPECT_TRUE(b.frames.empty());
  EXPECT_TRUE(b.events.empty());  // REC 32: still error-active
  EXPECT_EQ(broker.Port(pb).controller.rec, 32);
  EXPECT_EQ(broker.Port(pb).rx_errors, 32u);
  EXPECT_EQ(broker.Stats("can0").error_frames, 32u);

  // Bus-off: nothing is sent.
  EXPECT_EQ(broker.Submit(pa, Frame("181#03")), 0u);
  EXPECT_EQ(broker.Port(pa).bus_off_drops, 3u);

  // Automatic recovery after 128 × 11 = 1408 bit times (2816 µs at 500 kbit/s).
  broker.Faults("can0").Clear();
  const BusTime recovered_at = bus_off_at + Bits(kBusOffRecoveryBits);
  ASSERT_EQ(recovered_at - bus_off_at, 2816us);
  s.AdvanceTo(T(recovered_at - 1ns));
  EXPECT_EQ(a.events.size(), 2u);
  s.AdvanceTo(T(recovered_at));
  ASSERT_EQ(a.events.size(), 3u);
  EXPECT_EQ(a.events[2].state, ControllerState::kErrorActive);
  EXPECT_EQ(a.events[2].tec, 0);
  EXPECT_EQ(a.event_times[2], recovered_at);

  broker.Submit(pa, Frame("181#04"));
  s.Advance(1ms);
  EXPECT_EQ(b.Ids(), (std::vector<std::string>{"181#04"}));
}

// Direct controller fault: the port is forced bus-off now and its queue dropped.
TEST_F(Confinement, ForceBusOffAndAutomaticRecovery) {
  const PortId pa = Add(a);
  Add(b);
  s.Advance(1ms);
  const CanFrame frames[] = {Frame("181#01"), Frame("181#02")};
  broker.Submit(pa, frames);
  EXPECT_TRUE(broker.Faults("can0").ForceBusOff(pa));
  EXPECT_FALSE(broker.Faults("can0").ForceBusOff(pa));  // already bus-off
  ASSERT_EQ(a.events.size(), 1u);
  EXPECT_EQ(a.events[0].state, ControllerState::kBusOff);
  EXPECT_EQ(a.events[0].tec, 256);
  EXPECT_EQ(broker.Port(pa).bus_off_drops, 2u);
  s.Advance(Bits(kBusOffRecoveryBits) - 1ns);
  EXPECT_EQ(broker.Port(pa).controller.state, ControllerState::kBusOff);
  s.Advance(1ns);
  EXPECT_EQ(a.States(),
            (std::vector<ControllerState>{ControllerState::kBusOff, ControllerState::kErrorActive}));
  EXPECT_EQ(a.event_times[1], 1ms + 2816us);
  EXPECT_TRUE(b.frames.empty());
}

TEST_F(Confinement, ForceBusOffOfAPortOnAnotherBusIsRefused) {
  broker.AddBus({.name = "can1"});
  const PortId other = broker.Attach("can1", "x", c);
  EXPECT_THROW(broker.Faults("can0").ForceBusOff(other), std::invalid_argument);
}

// Recovery on command (auto recovery off, like a Linux interface with restart-ms 0).
TEST(ConfinementOnCommand, ABusOffPortStaysOffUntilRecoveredOnCommand) {
  SimulatedScheduler s;
  Broker broker(s);
  broker.AddBus({.name = "can0", .bitrate = kRate, .auto_recover = false});
  RecordingSink a{&s}, b{&s};
  const PortId pa = broker.Attach("can0", "a", a);
  broker.Attach("can0", "b", b);
  EXPECT_FALSE(broker.RecoverBusOff(pa));  // not bus-off
  broker.Faults("can0").ForceBusOff(pa);
  s.Advance(10s);
  EXPECT_EQ(a.States(), (std::vector<ControllerState>{ControllerState::kBusOff}));
  EXPECT_TRUE(broker.RecoverBusOff(pa));
  EXPECT_EQ(a.States(),
            (std::vector<ControllerState>{ControllerState::kBusOff, ControllerState::kErrorActive}));
  EXPECT_EQ(a.event_times[1], 10s);
  broker.Submit(pa, Frame("181#01"));
  s.Advance(1ms);
  EXPECT_EQ(b.Ids(), (std::vector<std::string>{"181#01"}));
}

// A bus-off controller takes no part in bus activity: it does not receive either.
TEST_F(Confinement, ABusOffPortReceivesNothing) {
  const PortId pa = Add(a);
  const PortId pb = Add(b);
  Add(c);
  broker.Faults("can0").ForceBusOff(pa);
  broker.Submit(pb, Frame("181#01"));
  s.Advance(1ms);
  EXPECT_TRUE(a.frames.empty());
  EXPECT_EQ(c.Ids(), (std::vector<std::string>{"181#01"}));
}

// A frame already on the wire when its sender is forced bus-off completes for the receivers; the
// sender gets no confirmation and its counters stay as bus-off left them.
TEST_F(Confinement, AFrameOnTheWireCompletesWhenItsSenderIsForcedBusOff) {
  const PortId pa = Add(a);
  Add(b);
  broker.Submit(pa, Frame("181#01"));
  s.Advance(10us);
  broker.Faults("can0").ForceBusOff(pa);
  s.Advance(1ms);
  EXPECT_EQ(b.Ids(), (std::vector<std::string>{"181#01"}));
  EXPECT_TRUE(a.confirmed.empty());
  EXPECT_EQ(broker.Port(pa).controller.tec, 256);
}

// Suspend transmission: after a has transmitted as an error-passive node it waits 8 bits after
// the intermission, so b's 200h (submitted together with a's 101h and 102h) goes before 102h.
TEST_F(Confinement, AnErrorPassiveTransmitterLetsOthersGoFirst) {
  const PortId pa = Add(a);
  const PortId pb = Add(b);
  Add(c);
  // 17 corrupted attempts (TEC 136), then success: TEC 135, error-passive.
  broker.Faults("can0").Add({.source = pa, .action = RuleAction::kCorrupt, .count = 17});
  broker.Submit(pa, Frame("100#"));
  s.Advance(100ms);
  ASSERT_EQ(broker.Port(pa).controller.tec, 135);
  ASSERT_EQ(broker.Port(pa).controller.state, ControllerState::kErrorPassive);
  c.frames.clear();

  const CanFrame a_frames[] = {Frame("101#"), Frame("102#")};
  broker.Submit(pa, a_frames);
  broker.Submit(pb, Frame("200#"));
  s.Advance(100ms);
  const BusTime t0 = 100ms;
  const BusTime e1 = t0 + FrameTime("101#", kRate);
  const BusTime e2 = e1 + FrameTime("200#", kRate);  // b starts right after the intermission
  const BusTime e3 = e2 + FrameTime("102#", kRate);
  EXPECT_EQ(c.Received(), (std::vector<std::string>{At("101#", e1), At("200#", e2), At("102#", e3)}));
}

// Receivers' counters change too (REC + 1 per corrupted frame, − 1 per valid one, rules 1 and 8)
// and each receiver is told about its own state changes.
TEST_F(Confinement, ReceiversAreToldTheirOwnStateChanges) {
  const PortId pa = Add(a);
  const PortId pb = Add(b);
  // 128 corrupted transfers from a: four times 32 attempts → bus-off → recovery → a sends again.
  a.on_event = [&](const ControllerEvent& e) {
    if (e.state == ControllerState::kErrorActive && e.tec == 0) broker.Submit(pa, Frame("181#01"));
  };
  broker.Faults("can0").Add({.source = pa, .action = RuleAction::kCorrupt, .count = 128});
  broker.Submit(pa, Frame("181#01"));
  s.Advance(1s);
  // REC reached 128 at the 128th error: error-passive; the rule is used up, so the 5th try is
  // received and REC drops back to 127: error-active.
  ASSERT_EQ(b.events.size(), 2u);
  EXPECT_EQ(b.events[0].state, ControllerState::kErrorPassive);
  EXPECT_EQ(b.events[0].rec, 128);
  EXPECT_EQ(b.events[1].state, ControllerState::kErrorActive);
  EXPECT_EQ(b.events[1].rec, 127);
  EXPECT_EQ(b.Ids(), (std::vector<std::string>{"181#01"}));
  EXPECT_EQ(broker.Port(pb).rx_errors, 128u);
  const auto a_states = a.States();
  EXPECT_EQ(std::count(a_states.begin(), a_states.end(), ControllerState::kBusOff), 4);
  // The frame and the event reach b in bus order: the frame, then the state change it caused.
  ASSERT_GE(b.log.size(), 2u);
  EXPECT_EQ(b.log[b.log.size() - 2].substr(0, 10), "rx 181#01@");
  EXPECT_EQ(b.log.back(), "error-active tec=0 rec=127");
}

}  // namespace
}  // namespace canfleet::broker
