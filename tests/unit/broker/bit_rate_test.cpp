// Ports at another bit rate than their bus (orchestrator/broker/README.md "Bit rate"): a node whose
// controller was switched by CiA 305 "activate bit timing" (CiA 305 §8.3.2) or by a device's
// bit-rate object. A controller samples a frame sent at another rate as noise: it detects an error
// (stuff or form error, ISO 11898-1:2015 §10.9.3-4) and counts it (§12.1.4.2 rule 1, REC + 1); it
// does not acknowledge (§6.10). A transmitter that nobody at its rate acknowledges sees the error
// flags of the others as a bit error (§10.9.2, rule 3: TEC + 8), so it goes error-passive and
// bus-off; alone on the bus it sees an ACK error as before.
#include <gtest/gtest.h>

#include <stdexcept>

#include "bus/physics/wire_model.hpp"
#include "orchestrator/broker/broker.hpp"
#include "tests/support/allocation_counter.hpp"
#include "tests/unit/broker/broker_test_support.hpp"

namespace canfleet::broker {
namespace {

using namespace test;
constexpr std::uint32_t kBus = 500'000;    // 2 µs per bit
constexpr std::uint32_t kOther = 250'000;  // 4 µs per bit

class BitRate : public ::testing::Test {
 protected:
  BitRate() { broker.AddBus({.name = "can0", .bitrate = kBus}); }
  PortId Add(RecordingSink& sink, AttachOptions options = {}) {
    return broker.Attach("can0", "port", sink, options);
  }
  /// The errors frames among what `sink` received.
  static std::size_t ErrorFrames(const RecordingSink& sink) {
    std::size_t n = 0;
    for (const auto& f : sink.frames)
      n += f.frame.error() ? 1 : 0;
    return n;
  }

  SimulatedScheduler s;
  Broker broker{s};
  RecordingSink a{&s}, b{&s}, c{&s};
};

// Given b at 250 kbit/s on a 500 kbit/s bus, when a sends, then c (at the bus's rate) receives
// and acknowledges the frame, while b sees an error frame in its place (same identifier, kError,
// at the end of the frame) and counts a receive error; b's PortStats say it runs at 250 kbit/s.
TEST_F(BitRate, APortAtAnotherRateSeesAnErrorFrameInsteadOfTheFrameAndCountsIt) {
  const PortId pa = Add(a);
  const PortId pb = Add(b, {.bitrate = kOther});
  Add(c);
  broker.Submit(pa, Frame("705#05"));
  s.Advance(10ms);
  const BusTime end = FrameTime("705#05", kBus);
  EXPECT_EQ(c.Received(), (std::vector<std::string>{At("705#05", end)}));
  EXPECT_EQ(a.Confirmed(), c.Received());
  EXPECT_EQ(b.Received(), (std::vector<std::string>{At("705#!", end)}));
  const PortStats port = broker.Port(pb);
  EXPECT_EQ(port.bitrate, kOther);
  EXPECT_EQ(port.controller.rec, 1);
  EXPECT_EQ(port.rx_errors, 1u);
  EXPECT_EQ(port.rx_frames, 0u);
  EXPECT_EQ(broker.Port(pa).bitrate, kBus);
  EXPECT_EQ(broker.Port(pa).controller.tec, 0);
  EXPECT_EQ(broker.Stats("can0").frames, 1u);
}

// REC + 1 per frame: at 128 the port is error-passive (§12.1.4.2 rule: REC > 127), with an event
// in bus order after the error frame that did it. It never goes bus-off by receiving.
TEST_F(BitRate, ThePortAtAnotherRateGoesErrorPassiveAfter128FramesAndStaysThere) {
  const PortId pa = Add(a);
  const PortId pb = Add(b, {.bitrate = kOther});
  Add(c);
  std::vector<CanFrame> frames(200, Frame("181#01"));
  broker.Submit(pa, frames);
  s.Advance(1s);
  EXPECT_EQ(c.frames.size(), 200u);
  EXPECT_EQ(ErrorFrames(b), 200u);
  EXPECT_EQ(b.frames.size(), 200u);
  ASSERT_EQ(b.events.size(), 1u);
  EXPECT_EQ(b.events[0].state, ControllerState::kErrorPassive);
  EXPECT_EQ(b.events[0].rec, 128);
  EXPECT_EQ(b.event_times[0], FrameTime("181#01", kBus) * 128);
  // In b's log the event follows its 128th error frame.
  EXPECT_EQ(b.log[128], "error-passive tec=0 rec=128");
  EXPECT_EQ(broker.Port(pb).controller.rec, 200);
  EXPECT_EQ(broker.Port(pb).controller.state, ControllerState::kErrorPassive);
}

// Given b at 250 kbit/s, when it sends (a node's heartbeat), then nobody at its rate acknowledges
// and a and c, at the bus's rate, destroy the frame with their error flags: each attempt lasts
// kRateErrorAttemptBits at b's rate, a and c see an error frame and count REC + 1, b counts TEC + 8
// (a bit error, not an ACK error). After 16 attempts b is error-passive (8 bits of suspend
// transmission between attempts), after 32 bus-off (its queue dropped); nobody ever receives 706#05.
// It recovers after 1408 bit times of its own rate.
TEST_F(BitRate, WhatAPortAtAnotherRateSendsReachesNobodyAndTakesItBusOff) {
  const PortId pa = Add(a);
  const PortId pb = Add(b, {.bitrate = kOther});
  const PortId pc = Add(c);
  broker.Submit(pb, Frame("706#05"));
  const BusTime attempt = BitTime(kRateErrorAttemptBits, kOther);
  const BusTime passive_at = attempt * 16;
  const BusTime bus_off_at = attempt * 32 + BitTime(16 * kSuspendTransmissionBits, kOther);
  s.AdvanceTo(T(bus_off_at));
  ASSERT_EQ(b.events.size(), 2u);
  EXPECT_EQ(b.events[0].state, ControllerState::kErrorPassive);
  EXPECT_EQ(b.events[0].tec, 128);
  EXPECT_EQ(b.event_times[0], passive_at);
  EXPECT_EQ(b.events[1].state, ControllerState::kBusOff);
  EXPECT_EQ(b.event_times[1], bus_off_at);
  EXPECT_TRUE(b.confirmed.empty());
  EXPECT_EQ(broker.Port(pb).queued, 0u);
  EXPECT_EQ(broker.Port(pb).tx_errors, 32u);
  for (const RecordingSink* other : {&a, &c}) {
    EXPECT_EQ(other->frames.size(), 32u);
    EXPECT_EQ(ErrorFrames(*other), 32u);
    EXPECT_EQ(ToCandump(other->frames[0].frame), "706#");
    EXPECT_EQ(other->frames[0].time, attempt);
  }
  EXPECT_EQ(broker.Port(pa).controller.rec, 32);
  EXPECT_EQ(broker.Port(pc).rx_errors, 32u);
  EXPECT_EQ(broker.Stats("can0").frames, 0u);
  EXPECT_EQ(broker.Stats("can0").error_frames, 32u);

  s.AdvanceTo(T(bus_off_at + BitTime(kBusOffRecoveryBits, kOther)));
  ASSERT_EQ(b.events.size(), 3u);
  EXPECT_EQ(b.events[2].state, ControllerState::kErrorActive);
}

// Alone on the bus but for a monitor (which drives nothing), a port at another rate sees ACK
// errors as any lone port: error-passive, never bus-off. The monitor sees the failed attempts.
TEST_F(BitRate, AlonePortAtAnotherRateGetsAckErrorsAndStaysErrorPassive) {
  const PortId pb = Add(b, {.bitrate = kOther});
  Add(c, {.listen_only = true, .error_frames = true});
  broker.Submit(pb, Frame("706#05"));
  s.Advance(1s);
  EXPECT_EQ(b.States(), (std::vector<ControllerState>{ControllerState::kErrorPassive}));
  EXPECT_EQ(broker.Port(pb).controller.tec, 128);
  EXPECT_EQ(broker.Port(pb).queued, 1u);
  ASSERT_FALSE(c.frames.empty());
  EXPECT_EQ(c.frames[0].time, BitTime(StuffedBits("706#05") + kAckErrorTailBits, kOther));
}

// Rates are per port, not per bus: two ports at 250 kbit/s exchange frames with each other (the
// transfer takes 250 kbit/s bit times) while the port at the bus's rate sees error frames. So does
// a whole bus whose nodes were all switched by LSS (CiA 305 §8.3.2: "activate bit timing" is
// meant for every node at once).
TEST_F(BitRate, PortsAtTheSameOtherRateTalkToEachOther) {
  const PortId pa = Add(a);
  const PortId pb = Add(b, {.bitrate = kOther});
  const PortId pc = Add(c, {.bitrate = kOther});
  broker.Submit(pb, Frame("706#05"));
  s.Advance(10ms);
  const BusTime end = FrameTime("706#05", kOther);
  EXPECT_EQ(c.Received(), (std::vector<std::string>{At("706#05", end)}));
  EXPECT_EQ(b.Confirmed(), c.Received());
  EXPECT_EQ(a.Received(), (std::vector<std::string>{At("706#!", end)}));
  EXPECT_EQ(broker.Port(pa).controller.rec, 1);
  EXPECT_EQ(broker.Port(pb).controller.tec, 0);
  EXPECT_EQ(broker.Port(pc).controller.rec, 0);
}

// The rule is symmetric: on a two-node bus where b runs at another rate, a's frames are b's noise
// and b destroys them: a goes bus-off just as b would.
TEST_F(BitRate, TwoNodesAtDifferentRatesDestroyEachOthersFrames) {
  const PortId pa = Add(a);
  Add(b, {.bitrate = kOther});
  broker.Submit(pa, Frame("705#05"));
  s.Advance(1s);
  EXPECT_EQ(a.States().front(), ControllerState::kErrorPassive);
  EXPECT_EQ(a.States()[1], ControllerState::kBusOff);
  EXPECT_EQ(ErrorFrames(b), b.frames.size());
  EXPECT_GE(b.frames.size(), 32u);
}

// Given b switched to 250 kbit/s, error-passive from the bus's traffic, when it is switched back
// (SetPortBitrate(port, 0): the bus's rate), then it receives the bus's frames again, each one
// counting REC down (above 127 it drops to 127, §12.1.4.2 rule 8) until it is error-active, and
// what it sends is acknowledged.
TEST_F(BitRate, BackAtTheBusRateThePortIsNormalAgain) {
  const PortId pa = Add(a);
  const PortId pb = Add(b);
  Add(c);
  EXPECT_TRUE(broker.SetPortBitrate(pb, kOther));
  broker.Submit(pa, std::vector<CanFrame>(130, Frame("181#01")));
  s.Advance(1s);
  EXPECT_EQ(ErrorFrames(b), 130u);
  EXPECT_EQ(broker.Port(pb).controller.state, ControllerState::kErrorPassive);

  EXPECT_TRUE(broker.SetPortBitrate(pb, 0));
  EXPECT_EQ(broker.Port(pb).bitrate, kBus);
  b.frames.clear();
  broker.Submit(pa, Frame("181#02"));
  s.Advance(10ms);
  ASSERT_EQ(b.frames.size(), 1u);
  EXPECT_EQ(ToCandump(b.frames[0].frame), "181#02");
  EXPECT_EQ(broker.Port(pb).controller.rec, 127);
  EXPECT_EQ(b.events.back().state, ControllerState::kErrorActive);
  broker.Submit(pb, Frame("706#05"));
  s.Advance(10ms);
  EXPECT_EQ(b.confirmed.size(), 1u);
  EXPECT_EQ(ToCandump(a.frames.back().frame), "706#05");
}

// Switching the rate of a port to the bus's own rate is the same as 0.
TEST_F(BitRate, StatingTheBusRateIsTheBusRate) {
  const PortId pa = Add(a);
  const PortId pb = Add(b, {.bitrate = kBus});
  broker.Submit(pa, Frame("705#05"));
  s.Advance(10ms);
  EXPECT_EQ(b.Ids(), (std::vector<std::string>{"705#05"}));
  EXPECT_EQ(broker.Port(pb).bitrate, kBus);
}

TEST_F(BitRate, RatesOutsideTheRangeAreRefused) {
  EXPECT_THROW(Add(a, {.bitrate = 5'000}), std::invalid_argument);
  EXPECT_THROW(Add(a, {.bitrate = 2'000'000}), std::invalid_argument);
  const PortId pb = Add(b);
  EXPECT_THROW(broker.SetPortBitrate(pb, 1'000'001), std::invalid_argument);
  EXPECT_FALSE(broker.SetPortBitrate(999, kOther));
  broker.Detach(pb);
  EXPECT_FALSE(broker.SetPortBitrate(pb, kOther));
}

// Unpaced buses have no time line but the same rule: the port at another rate gets error frames.
TEST(BitRateUnpaced, APortAtAnotherRateSeesErrorFrames) {
  SimulatedScheduler s;
  Broker broker(s);
  broker.AddBus({.name = "can0", .bitrate = kBus, .paced = false});
  RecordingSink a, b, c;
  const PortId pa = broker.Attach("can0", "a", a);
  const PortId pb = broker.Attach("can0", "b", b, {.bitrate = kOther});
  broker.Attach("can0", "c", c);
  broker.Submit(pa, Frame("705#05"));
  s.Advance(1ms);
  EXPECT_EQ(c.Ids(), (std::vector<std::string>{"705#05"}));
  EXPECT_EQ(b.Ids(), (std::vector<std::string>{"705#"}));
  EXPECT_TRUE(b.frames[0].frame.error());
  EXPECT_EQ(broker.Port(pb).controller.rec, 1);
}

// The frame path stays free of allocation with a port at another rate on the bus: its error
// frames go into the round's shared buffer like any frame addressed to one port.
TEST(BitRateAllocation, APortAtAnotherRateCostsNoAllocationPerFrame) {
  SimulatedScheduler s;
  Broker broker(s);
  broker.AddBus({.name = "can0", .bitrate = 1'000'000});
  struct Echo : PortSink {
    Echo(Broker& b, CanFrame f) : broker(b), frame(f) {}
    void Deliver(std::span<const TimedFrame> frames) override { received += frames.size(); }
    void ControllerChanged(const ControllerEvent&) override {}
    void TxConfirmed(std::span<const TimedFrame> frames) override {
      for (std::size_t i = 0; i < frames.size(); ++i)
        broker.Submit(id, frame);
    }
    Broker& broker;
    CanFrame frame;
    PortId id = 0;
    std::size_t received = 0;
  };
  Echo a(broker, Frame("181#0102030405060708")), b(broker, Frame("182#01")), off(broker, Frame("183#"));
  a.id = broker.Attach("can0", "a", a);
  b.id = broker.Attach("can0", "b", b);
  off.id = broker.Attach("can0", "off", off, {.bitrate = 250'000});
  for (Echo* e : {&a, &b})
    for (int i = 0; i < 8; ++i)
      broker.Submit(e->id, Frame("123#"));
  s.Advance(100ms);  // warm-up
  const auto before = canfleet::test::AllocationCount();
  const std::size_t seen = off.received;
  s.Advance(100ms);
  EXPECT_EQ(canfleet::test::AllocationCount() - before, 0u);
  EXPECT_GT(off.received - seen, 500u);  // error frames did flow to it
}

}  // namespace
}  // namespace canfleet::broker
