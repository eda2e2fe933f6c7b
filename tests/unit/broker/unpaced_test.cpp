// Unpaced buses: no timing model, FIFO in submission order across ports, batch delivery
// (issue 4, "Unpaced mode").
#include <gtest/gtest.h>

#include "orchestrator/broker/broker.hpp"
#include "tests/unit/broker/broker_test_support.hpp"

namespace canfleet::broker {
namespace {

using namespace test;

class Unpaced : public ::testing::Test {
 protected:
  SimulatedScheduler s;
  Broker broker{s};
  bool bus_added = (broker.AddBus({.name = "fast", .paced = false}), true);
  RecordingSink a{&s}, b{&s}, c{&s};
  PortId pa = broker.Attach("fast", "a", a);
  PortId pb = broker.Attach("fast", "b", b);
  PortId pc = broker.Attach("fast", "c", c);
};

// No arbitration: 700h submitted first goes first; one round, one batch, submission times.
TEST_F(Unpaced, FramesGoInSubmissionOrderInOneBatch) {
  s.Advance(3ms);
  broker.Submit(pa, Frame("700#01"));
  broker.Submit(pb, Frame("100#02"));
  broker.Submit(pa, Frame("080#03"));
  EXPECT_TRUE(c.frames.empty());  // delivered by the next round, not inside Submit
  s.Advance(0ns);
  EXPECT_EQ(c.Received(), (std::vector<std::string>{"700#01@3000000", "100#02@3000000", "080#03@3000000"}));
  EXPECT_EQ(c.deliver_calls, 1);
  EXPECT_EQ(b.Ids(), (std::vector<std::string>{"700#01", "080#03"}));
  EXPECT_EQ(a.Ids(), (std::vector<std::string>{"100#02"}));
  EXPECT_EQ(a.Confirmed(), (std::vector<std::string>{"700#01@3000000", "080#03@3000000"}));
  EXPECT_EQ(a.confirm_calls, 1);
  EXPECT_DOUBLE_EQ(broker.Stats("fast").load_percent, 0.0);
  EXPECT_EQ(broker.Stats("fast").frames, 3u);
}

// Frames submitted from inside a delivery go in the next round, 1 ns later on the scheduler's
// time line (no recursion; two nodes answering each other cannot spin at one instant), with the
// time they were submitted.
TEST_F(Unpaced, RepliesFromInsideDeliverGoInTheNextRound) {
  int rounds = 0;
  b.on_deliver = [&](std::span<const TimedFrame> frames) {
    ++rounds;
    for (const auto& f : frames)
      if (f.frame.id == 0x601) broker.Submit(pb, Frame("581#60"));
  };
  broker.Submit(pa, Frame("601#40"));
  s.Advance(0ns);
  EXPECT_EQ(c.Ids(), (std::vector<std::string>{"601#40"}));
  EXPECT_TRUE(a.frames.empty());
  s.Advance(1ns);
  EXPECT_EQ(a.Received(), (std::vector<std::string>{"581#60@0"}));
  EXPECT_EQ(c.Ids(), (std::vector<std::string>{"601#40", "581#60"}));
  EXPECT_EQ(c.deliver_calls, 2);
  EXPECT_EQ(rounds, 1);
}

TEST_F(Unpaced, CorruptionStillCountsAndBusOffStillStopsThePort) {
  broker.Faults("fast").Add({.source = pa, .action = RuleAction::kCorrupt});
  broker.Submit(pa, Frame("181#01"));
  s.Advance(0ns);
  EXPECT_EQ(a.States(),
            (std::vector<ControllerState>{ControllerState::kErrorPassive, ControllerState::kBusOff}));
  EXPECT_EQ(broker.Port(pa).tx_errors, 32u);
  EXPECT_EQ(broker.Port(pb).controller.rec, 32);
  EXPECT_TRUE(b.frames.empty());
}

// A lone unpaced port gets one ACK error per round and waits (instead of retrying forever in
// zero time) until another port attaches.
TEST(UnpacedAlone, ALonePortWaitsForAnotherPort) {
  SimulatedScheduler s;
  Broker broker(s);
  broker.AddBus({.name = "fast", .paced = false});
  RecordingSink a, b;
  const PortId pa = broker.Attach("fast", "a", a);
  broker.Submit(pa, Frame("181#01"));
  s.Advance(1s);
  EXPECT_EQ(broker.Port(pa).tx_errors, 1u);
  EXPECT_EQ(broker.Port(pa).queued, 1u);
  broker.Attach("fast", "b", b);
  s.Advance(0ns);
  EXPECT_EQ(b.Ids(), (std::vector<std::string>{"181#01"}));
  EXPECT_EQ(broker.Port(pa).controller.tec, 7);
}

}  // namespace
}  // namespace canfleet::broker
