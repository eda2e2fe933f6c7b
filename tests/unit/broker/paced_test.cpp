// Paced buses: the wire's time line. Frame lengths from bus/physics/frame_timing.hpp (ISO 11898-1:2015
// §10.4 frame formats, §10.5 bit stuffing, 3 bits of intermission counted in each frame); a frame
// pending during a transfer starts at the first bit after the intermission (§10.4 interframe space).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "orchestrator/broker/broker.hpp"
#include "tests/unit/broker/broker_test_support.hpp"

namespace canfleet::broker {
namespace {

using namespace test;

class PacedBus : public ::testing::Test {
 protected:
  SimulatedScheduler s;
  Broker broker{s};
  bool bus_added = (broker.AddBus({.name = "can0", .bitrate = 500'000}), true);  // 2 µs per bit
  RecordingSink a{&s}, b{&s}, c{&s}, listener{&s};
  PortId pa = broker.Attach("can0", "a", a);
  PortId pb = broker.Attach("can0", "b", b);
  PortId pc = broker.Attach("can0", "c", c);
  PortId pl = broker.Attach("can0", "listener", listener);
};

// Worked by hand (bits from the frame-timing tests): 000# is 53 bits, 123#1122334455667788 is
// 98 + 1 stuff + 13 = 112 bits, 701#05 is 42 + 3 + 13 = 58 bits. At 500 kbit/s: 106 µs, 224 µs,
// 116 µs, so the frames end at 106, 330 and 446 µs.
TEST_F(PacedBus, BackToBackFramesEndAtTheSumOfTheirExactDurations) {
  broker.Submit(pa, Frame("123#1122334455667788"));
  broker.Submit(pb, Frame("701#05"));
  broker.Submit(pc, Frame("000#"));
  s.Advance(10ms);
  EXPECT_EQ(listener.Received(),
            (std::vector<std::string>{"000#@106000", "123#1122334455667788@330000", "701#05@446000"}));
  EXPECT_EQ(
      FrameTime("000#", 500'000) + FrameTime("123#1122334455667788", 500'000) + FrameTime("701#05", 500'000),
      446us);
}

TEST_F(PacedBus, AnIdleBusStartsAFrameWhenItIsSubmitted) {
  s.Advance(5ms);
  broker.Submit(pa, Frame("000#"));
  s.Advance(105us);
  EXPECT_TRUE(listener.frames.empty());  // still on the wire
  s.Advance(1us);
  EXPECT_EQ(listener.Received(), (std::vector<std::string>{"000#@5106000"}));
}

// Given 700h on the wire, when 100h and 050h are submitted during it, then both wait for the end
// of the transfer and arbitrate then: 050h first.
TEST_F(PacedBus, FramesSubmittedDuringATransferArbitrateAtItsEnd) {
  broker.Submit(pa, Frame("700#"));
  s.Advance(20us);
  broker.Submit(pb, Frame("100#"));
  broker.Submit(pc, Frame("050#"));
  s.Advance(10ms);
  const BusTime e1 = FrameTime("700#", 500'000);
  const BusTime e2 = e1 + FrameTime("050#", 500'000);
  const BusTime e3 = e2 + FrameTime("100#", 500'000);
  EXPECT_EQ(listener.Received(), (std::vector<std::string>{At("700#", e1), At("050#", e2), At("100#", e3)}));
}

// A frame submitted just after an arbitration started waits, even with a lower identifier.
TEST_F(PacedBus, AFrameSubmittedAfterStartOfFrameCannotJoinThatArbitration) {
  broker.Submit(pa, Frame("7FF#"));
  s.Advance(0ns);  // the arbitration at t = 0 has happened
  broker.Submit(pb, Frame("000#"));
  s.Advance(10ms);
  EXPECT_EQ(listener.Ids(), (std::vector<std::string>{"7FF#", "000#"}));
}

TEST_F(PacedBus, TheSenderGetsATxConfirmationWithTheSameBusTime) {
  broker.Submit(pa, Frame("181#0102"));
  s.Advance(10ms);
  const BusTime end = FrameTime("181#0102", 500'000);
  EXPECT_TRUE(a.frames.empty());  // no echo of its own frame
  EXPECT_EQ(a.Confirmed(), (std::vector<std::string>{At("181#0102", end)}));
  EXPECT_EQ(b.Received(), (std::vector<std::string>{At("181#0102", end)}));
  EXPECT_EQ(c.Received(), b.Received());
  EXPECT_EQ(broker.Port(pa).tx_frames, 1u);
  EXPECT_EQ(broker.Port(pb).rx_frames, 1u);
}

// A node that answers from inside Deliver: its reply is submitted at the request's end of frame
// (simulated time) and starts right then.
TEST_F(PacedBus, AReplyFromInsideDeliverStartsAtTheEndOfTheRequest) {
  b.on_deliver = [&](std::span<const TimedFrame> frames) {
    for (const auto& f : frames)
      if (f.frame.id == 0x605) broker.Submit(pb, Frame("585#4B17100000000000"));
  };
  broker.Submit(pa, Frame("605#4017100000000000"));
  s.Advance(10ms);
  const BusTime request_end = FrameTime("605#4017100000000000", 500'000);
  const BusTime reply_end = request_end + FrameTime("585#4B17100000000000", 500'000);
  EXPECT_EQ(a.Received(), (std::vector<std::string>{At("585#4B17100000000000", reply_end)}));
  EXPECT_EQ(listener.Received(), (std::vector<std::string>{At("605#4017100000000000", request_end),
                                                           At("585#4B17100000000000", reply_end)}));
}

/// A scenario with queues on several ports, a submission in the middle and a late joiner;
/// returns what the listener saw.
template <class Sched, class Step>
std::vector<std::string> RunScenario(Sched& sched, Step step, int* deliver_calls) {
  Broker broker(sched);
  broker.AddBus({.name = "can0", .bitrate = 125'000});
  RecordingSink a, b, c, listener;
  const PortId pa = broker.Attach("can0", "a", a);
  const PortId pb = broker.Attach("can0", "b", b);
  const PortId pc = broker.Attach("can0", "c", c);
  broker.Attach("can0", "listener", listener);
  const CanFrame a_frames[] = {Frame("181#01"), Frame("181#02"), Frame("181#03")};
  const CanFrame b_frames[] = {Frame("182#AAAA"), Frame("082#"), Frame("1FFFFFFF#0011223344556677")};
  broker.Submit(pa, a_frames);
  broker.Submit(pb, b_frames);
  step(broker, 700us);  // time passes; the bus may or may not have been served meanwhile
  broker.Submit(pc, Frame("080#FF"));
  step(broker, 20ms);
  *deliver_calls = listener.deliver_calls;
  return listener.Received();
}

// The time line does not depend on when the timer fires: (1) simulated time (every timer on time),
// (2) a late driver woken every 3 µs, (3) a late driver woken once at the end. Same frames, same
// timestamps; only the batching differs.
TEST(PacedTimeLine, TimestampsDoNotDependOnWhenTheTimerFires) {
  int calls_exact = 0, calls_small = 0, calls_big = 0;
  SimulatedScheduler exact;
  auto exact_run = RunScenario(
      exact, [&](Broker&, Duration until) { exact.AdvanceTo(T(until)); }, &calls_exact);

  LateScheduler small;
  auto small_run = RunScenario(
      small,
      [&](Broker&, Duration until) {
        while (small.Now() < T(until))
          small.JumpTo(std::min(small.Now() + 3us, T(until)));
      },
      &calls_small);

  LateScheduler big;
  auto big_run = RunScenario(
      big,
      [&](Broker&, Duration until) {
        // The event loop is busy until `until`: time passes, no timer runs. Only the final step
        // wakes it, so the whole scenario is processed in one round.
        big.SetNow(T(until));
        if (until == 20ms) big.Wake();
      },
      &calls_big);

  ASSERT_EQ(exact_run.size(), 7u);
  EXPECT_EQ(small_run, exact_run);
  EXPECT_EQ(big_run, exact_run);
  EXPECT_EQ(calls_exact, 7);
  EXPECT_EQ(calls_big, 1);  // one batch
  // 080h was submitted at 700 µs, while 181#02 was on the wire: it wins the next arbitration.
  EXPECT_EQ(exact_run[1].substr(0, 6), "181#02");
  EXPECT_EQ(exact_run[2].substr(0, 6), "080#FF");
}

// 100 % offered load at 125 kbit/s: two ports with full queues keep the bus busy, so over the
// 1 s window the bus is busy all the time and frames/s is 1 s / frame duration.
TEST(PacedLoad, FullOfferedLoadIsExactlyOneHundredPercent) {
  SimulatedScheduler s;
  Broker broker(s);
  broker.AddBus({.name = "can0", .bitrate = 125'000});
  RecordingSink a, b, listener;
  const PortId pa = broker.Attach("can0", "a", a);
  const PortId pb = broker.Attach("can0", "b", b);
  broker.Attach("can0", "listener", listener);
  const std::vector<CanFrame> burst_a(1024, Frame("201#0011223344556677"));
  const std::vector<CanFrame> burst_b(1024, Frame("202#0011223344556677"));
  EXPECT_EQ(broker.Submit(pa, burst_a), 1024u);
  EXPECT_EQ(broker.Submit(pb, burst_b), 1024u);
  s.Advance(1500ms);
  const BusStats stats = broker.Stats("can0");
  EXPECT_EQ(stats.window, 1s);
  EXPECT_DOUBLE_EQ(stats.load_percent, 100.0);
  // frames/s counts the transfers that ended within (0.5 s, 1.5 s].
  const auto in_window =
      std::count_if(listener.frames.begin(), listener.frames.end(),
                    [](const TimedFrame& f) { return f.time > 500ms && f.time <= 1500ms; });
  EXPECT_DOUBLE_EQ(stats.frames_per_s, static_cast<double>(in_window));
  // Between the rates of the two frame lengths (912 µs and 920 µs: different stuffing).
  EXPECT_GE(stats.frames_per_s, std::floor(1e9 / 920'000.0));
  EXPECT_LE(stats.frames_per_s, std::ceil(1e9 / 912'000.0));
  EXPECT_EQ(FrameTime("201#0011223344556677", 125'000), 912us);
  EXPECT_EQ(stats.error_frames_per_s, 0.0);
  EXPECT_EQ(broker.Port(pa).queue_drops + broker.Port(pb).queue_drops, 0u);
}

TEST(PacedLoad, OneFrameInOneSecondIsItsDurationOverTheWindow) {
  SimulatedScheduler s;
  Broker broker(s);
  broker.AddBus({.name = "can0", .bitrate = 500'000});
  RecordingSink a, b;
  const PortId pa = broker.Attach("can0", "a", a);
  broker.Attach("can0", "b", b);
  broker.Submit(pa, Frame("000#"));  // 53 bits = 106 µs
  s.Advance(1s);
  const BusStats stats = broker.Stats("can0");
  EXPECT_DOUBLE_EQ(stats.load_percent, 100.0 * 106'000 / 1e9);
  EXPECT_DOUBLE_EQ(stats.frames_per_s, 1.0);
  // The window (now - 1 s, now] still holds the frame (end at 106 µs) until now = 1 s + 106 µs.
  s.Advance(105us);
  EXPECT_DOUBLE_EQ(broker.Stats("can0").frames_per_s, 1.0);
  s.Advance(1us);
  EXPECT_DOUBLE_EQ(broker.Stats("can0").frames_per_s, 0.0);
  EXPECT_DOUBLE_EQ(broker.Stats("can0").load_percent, 0.0);
}

// A young bus measures over its lifetime: 50 % load when busy half of the 2 ms it has existed.
TEST(PacedLoad, AYoungBusMeasuresOverItsLifetime) {
  SimulatedScheduler s;
  Broker broker(s);
  broker.AddBus({.name = "can0", .bitrate = 500'000});
  RecordingSink a, b;
  const PortId pa = broker.Attach("can0", "a", a);
  broker.Attach("can0", "b", b);
  broker.Submit(pa, Frame("000#"));  // 106 µs
  s.Advance(212us);
  const BusStats stats = broker.Stats("can0");
  EXPECT_EQ(stats.window, 212us);
  EXPECT_DOUBLE_EQ(stats.load_percent, 50.0);
}

TEST(PacedStats, BusiestIdentifiersFirst) {
  SimulatedScheduler s;
  Broker broker(s);
  broker.AddBus({.name = "can0"});
  RecordingSink a, b;
  const PortId pa = broker.Attach("can0", "a", a);
  broker.Attach("can0", "b", b);
  const CanFrame frames[] = {Frame("381#"), Frame("181#"), Frame("281#"), Frame("181#"),
                             Frame("281#"), Frame("181#"), Frame("181#R")};
  broker.Submit(pa, frames);
  s.Advance(1s);
  const BusStats stats = broker.Stats("can0", 3);
  ASSERT_EQ(stats.top_ids.size(), 3u);
  EXPECT_EQ(stats.top_ids[0].id, 0x181u);
  EXPECT_EQ(stats.top_ids[0].frames, 4u);  // remote frames count for their COB-ID too
  EXPECT_DOUBLE_EQ(stats.top_ids[0].frames_per_s, 4.0);
  EXPECT_EQ(stats.top_ids[1].id, 0x281u);
  EXPECT_EQ(stats.top_ids[2].id, 0x381u);
  EXPECT_EQ(stats.frames, 7u);
  EXPECT_EQ(stats.deliveries, 7u);
  EXPECT_EQ(stats.ports, 2u);
}

}  // namespace
}  // namespace canfleet::broker
