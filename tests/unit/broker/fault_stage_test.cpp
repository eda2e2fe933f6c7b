// The fault stage between arbitration and delivery (issue 4, "The broker"; design decision 3: a
// fault looks to every node as it would on a real bus). Corruption and its counter consequences
// are in error_confinement_test.cpp.
#include "orchestrator/broker/fault_stage.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include "orchestrator/broker/broker.hpp"
#include "tests/unit/broker/broker_test_support.hpp"

namespace canfleet::broker {
namespace {

using namespace test;
constexpr std::uint32_t kRate = 500'000;

class Faults : public ::testing::Test {
 protected:
  FaultStage& stage() { return broker.Faults("can0"); }

  SimulatedScheduler s;
  Broker broker{s};
  bool bus_added = (broker.AddBus({.name = "can0", .bitrate = kRate}), true);
  RecordingSink a{&s}, b{&s}, c{&s};
  PortId pa = broker.Attach("can0", "a", a);
  PortId pb = broker.Attach("can0", "b", b);
  PortId pc = broker.Attach("can0", "c", c);
};

// A dropped heartbeat is simply never seen; the transfer itself succeeded on the wire.
TEST_F(Faults, DropByCobIdAndMask) {
  stage().Add({.id = 0x700, .mask = 0x780, .action = RuleAction::kDrop});  // every heartbeat 701h..77Fh
  const CanFrame frames[] = {Frame("705#05"), Frame("181#01"), Frame("77F#7F")};
  broker.Submit(pa, frames);
  s.Advance(10ms);
  EXPECT_EQ(b.Ids(), (std::vector<std::string>{"181#01"}));
  EXPECT_EQ(c.Ids(), (std::vector<std::string>{"181#01"}));
  EXPECT_EQ(a.confirmed.size(), 3u);
  EXPECT_EQ(broker.Port(pb).fault_drops, 2u);
  EXPECT_EQ(broker.Stats("can0").fault_drops, 4u);
  EXPECT_EQ(broker.Port(pb).controller.rec, 0);
}

TEST_F(Faults, DropOnlyForTheListedReceivers) {
  stage().Add({.receivers = {pc}, .action = RuleAction::kDrop});
  broker.Submit(pa, Frame("181#01"));
  s.Advance(10ms);
  EXPECT_EQ(b.Ids(), (std::vector<std::string>{"181#01"}));
  EXPECT_TRUE(c.frames.empty());
}

TEST_F(Faults, MatchBySourcePortAndFormat) {
  stage().Add({.source = pa, .action = RuleAction::kDrop});
  stage().Add({.extended = true, .action = RuleAction::kDrop});
  broker.Submit(pa, Frame("181#01"));
  broker.Submit(pb, Frame("182#02"));
  broker.Submit(pb, Frame("00000182#03"));
  s.Advance(10ms);
  EXPECT_EQ(c.Ids(), (std::vector<std::string>{"182#02"}));
  EXPECT_TRUE(b.frames.empty());
}

// Delayed frames are stamped with their delivery time and keep their order; other receivers and
// the sender see the wire's times.
TEST_F(Faults, DelayKeepsOrderAndStampsTheDeliveryTime) {
  stage().Add({.receivers = {pb}, .action = RuleAction::kDelay, .delay = 5ms});
  const CanFrame frames[] = {Frame("181#01"), Frame("181#02")};
  broker.Submit(pa, frames);
  const BusTime e1 = FrameTime("181#01", kRate);
  const BusTime e2 = e1 + FrameTime("181#02", kRate);
  s.Advance(5ms + e1 - 1ns);
  EXPECT_TRUE(b.frames.empty());
  s.Advance(1s);
  EXPECT_EQ(b.Received(), (std::vector<std::string>{At("181#01", e1 + 5ms), At("181#02", e2 + 5ms)}));
  EXPECT_EQ(c.Received(), (std::vector<std::string>{At("181#01", e1), At("181#02", e2)}));
  EXPECT_EQ(a.Confirmed(), c.Received());
  EXPECT_EQ(broker.Stats("can0").fault_delays, 2u);
}

/// 20 frames from a, delayed to b by 1 ms + 0..500 µs: b's times.
std::vector<BusTime> JitteredTimes(std::uint64_t seed) {
  SimulatedScheduler s;
  Broker broker(s);
  broker.AddBus({.name = "can0", .bitrate = kRate});
  RecordingSink a, b;
  const PortId pa = broker.Attach("can0", "a", a);
  broker.Attach("can0", "b", b);
  broker.Faults("can0").Add({.action = RuleAction::kDelay, .delay = 1ms, .jitter = 500us, .seed = seed});
  for (int i = 0; i < 20; ++i)
    broker.Submit(pa, CanFrame::Data(0x181, {static_cast<std::uint8_t>(i)}));
  s.Advance(1s);
  std::vector<BusTime> times;
  for (const auto& f : b.frames)
    times.push_back(f.time);
  return times;
}

// Jitter is drawn per receiver from the rule's seeded generator: the same seed gives the same
// times; frames may be reordered by it, but each receiver's batch is in time order.
TEST(FaultsSeeded, JitterIsDeterministicPerSeedAndBounded) {
  const auto first = JitteredTimes(42);
  ASSERT_EQ(first.size(), 20u);
  EXPECT_EQ(JitteredTimes(42), first);
  EXPECT_NE(JitteredTimes(43), first);
  EXPECT_TRUE(std::is_sorted(first.begin(), first.end()));
  BusTime end{};
  std::vector<BusTime> ends;
  for (int i = 0; i < 20; ++i) {
    end += BitTime(CountFrameBits(CanFrame::Data(0x181, {static_cast<std::uint8_t>(i)})).total(), kRate);
    ends.push_back(end);
  }
  for (BusTime t : first) {
    const bool within =
        std::any_of(ends.begin(), ends.end(), [&](BusTime e) { return t >= e + 1ms && t <= e + 1500us; });
    EXPECT_TRUE(within) << t.count();
  }
}

// Duplicate: the transfer is repeated once on the wire; receivers get two copies with their own
// end-of-frame times, the sender one confirmation.
TEST_F(Faults, DuplicateRepeatsTheTransferOnTheWire) {
  stage().Add({.id = 0x181, .mask = 0x7FF, .action = RuleAction::kDuplicate, .count = 1});
  const CanFrame frames[] = {Frame("181#01"), Frame("181#02")};
  broker.Submit(pa, frames);
  s.Advance(10ms);
  const BusTime d1 = FrameTime("181#01", kRate), d2 = FrameTime("181#02", kRate);
  EXPECT_EQ(b.Received(),
            (std::vector<std::string>{At("181#01", d1), At("181#01", 2 * d1), At("181#02", 2 * d1 + d2)}));
  EXPECT_EQ(a.Confirmed(), (std::vector<std::string>{At("181#01", d1), At("181#02", 2 * d1 + d2)}));
  EXPECT_EQ(broker.Port(pa).tx_frames, 3u);  // transfers on the wire
}

/// 1000 frames through a drop rule with probability 0.25: what b received.
std::vector<std::string> DropWithProbability(std::uint64_t seed) {
  SimulatedScheduler s;
  Broker broker(s);
  broker.AddBus({.name = "can0", .bitrate = 1'000'000});
  RecordingSink a, b;
  const PortId pa = broker.Attach("can0", "a", a);
  broker.Attach("can0", "b", b);
  const RuleId id =
      broker.Faults("can0").Add({.action = RuleAction::kDrop, .probability = 0.25, .seed = seed});
  for (int i = 0; i < 1000; ++i)
    broker.Submit(pa,
                  CanFrame::Data(0x181, {static_cast<std::uint8_t>(i), static_cast<std::uint8_t>(i >> 8)}));
  s.Advance(1s);
  const auto rules = broker.Faults("can0").List();
  EXPECT_EQ(rules.at(0).id, id);
  EXPECT_EQ(rules.at(0).hits + b.frames.size(), 1000u);
  return b.Ids();
}

// Probability with a seed: the same frames are hit on every run.
TEST(FaultsSeeded, ProbabilityIsSeededAndRepeatable) {
  const auto first = DropWithProbability(7);
  EXPECT_EQ(DropWithProbability(7), first);
  EXPECT_NE(DropWithProbability(8), first);
  EXPECT_GT(first.size(), 700u);  // ≈ 750 pass
  EXPECT_LT(first.size(), 800u);
}

TEST_F(Faults, ProbabilityZeroNeverFiresOneAlwaysFires) {
  stage().Add({.receivers = {pb}, .action = RuleAction::kDrop, .probability = 0.0});
  stage().Add({.receivers = {pc}, .action = RuleAction::kDrop, .probability = 1.0});
  broker.Submit(pa, Frame("181#01"));
  s.Advance(10ms);
  EXPECT_EQ(b.Ids(), (std::vector<std::string>{"181#01"}));
  EXPECT_TRUE(c.frames.empty());
}

TEST_F(Faults, ARuleExpiresAfterItsCount) {
  const RuleId id = stage().Add({.action = RuleAction::kDrop, .count = 3});
  for (int i = 1; i <= 5; ++i)
    broker.Submit(pa, CanFrame::Data(0x181, {static_cast<std::uint8_t>(i)}));
  s.Advance(250us);  // two frames of 110 µs sent
  ASSERT_EQ(stage().List().size(), 1u);
  EXPECT_EQ(stage().List()[0].id, id);
  EXPECT_EQ(stage().List()[0].remaining, 1u);
  s.Advance(10ms);
  EXPECT_EQ(b.Ids(), (std::vector<std::string>{"181#04", "181#05"}));
  EXPECT_TRUE(stage().List().empty());
  EXPECT_FALSE(stage().Remove(id));
}

// A rule with a lifetime applies to transfers that start within it (bus time).
TEST_F(Faults, ARuleExpiresAfterItsLifetime) {
  s.Advance(1ms);
  stage().Add({.action = RuleAction::kDrop, .lifetime = 2ms});
  ASSERT_EQ(stage().List().size(), 1u);
  EXPECT_EQ(stage().List()[0].expires, T(3ms));
  broker.Submit(pa, Frame("181#01"));  // starts at 1 ms: dropped
  s.Advance(1990us);
  broker.Submit(pa, Frame("181#02"));  // starts at 2.99 ms: dropped
  s.Advance(10us);
  EXPECT_TRUE(stage().List().empty());  // expired at 3 ms
  broker.Submit(pa, Frame("181#03"));   // starts at 3 ms: delivered
  s.Advance(10ms);
  EXPECT_EQ(b.Ids(), (std::vector<std::string>{"181#03"}));
}

// A rule does not reach back: a transfer that started before the rule was added is untouched,
// even when the broker processes it later (late timer).
TEST(FaultsOnTheTimeLine, ARuleAppliesFromTheMomentItWasAdded) {
  LateScheduler s;
  Broker broker(s);
  broker.AddBus({.name = "can0", .bitrate = kRate});
  RecordingSink a, b;
  const PortId pa = broker.Attach("can0", "a", a);
  broker.Attach("can0", "b", b);
  const CanFrame frames[] = {Frame("181#01"), Frame("181#02")};
  broker.Submit(pa, frames);
  const BusTime e1 = FrameTime("181#01", kRate);
  s.SetNow(T(e1 - 1us));  // 181#01 is on the wire, 181#02 is not; nothing processed yet
  broker.Faults("can0").Add({.action = RuleAction::kDrop});
  s.JumpTo(T(10ms));
  EXPECT_EQ(b.Ids(), (std::vector<std::string>{"181#01"}));
}

TEST_F(Faults, ListRemoveClear) {
  const RuleId r1 = stage().Add({.action = RuleAction::kDrop});
  const RuleId r2 = stage().Add({.id = 0x705, .mask = 0x7FF, .action = RuleAction::kDelay, .delay = 1ms});
  const RuleId r3 = stage().Add({.action = RuleAction::kCorrupt, .count = 5});
  EXPECT_EQ(r1, 1u);
  EXPECT_EQ(r2, 2u);
  EXPECT_EQ(r3, 3u);
  EXPECT_TRUE(stage().Remove(r2));
  EXPECT_FALSE(stage().Remove(r2));
  auto list = stage().List();
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[0].id, r1);
  EXPECT_EQ(list[1].id, r3);
  EXPECT_EQ(list[1].rule.action, RuleAction::kCorrupt);
  EXPECT_EQ(list[1].remaining, 5u);
  stage().Clear();
  EXPECT_TRUE(stage().List().empty());
  EXPECT_EQ(stage().Add({}), 4u);  // ids are never reused
  EXPECT_STREQ(ToString(RuleAction::kDuplicate), "duplicate");
}

TEST_F(Faults, InvalidRulesAreRefused) {
  EXPECT_THROW(stage().Add({.probability = 1.5}), std::invalid_argument);
  EXPECT_THROW(stage().Add({.probability = -0.1}), std::invalid_argument);
  EXPECT_THROW(stage().Add({.action = RuleAction::kDelay, .delay = -1ms}), std::invalid_argument);
  EXPECT_THROW(stage().Add({.lifetime = 0ms}), std::invalid_argument);
  EXPECT_THROW(stage().Add({.count = 0}), std::invalid_argument);
  EXPECT_TRUE(stage().List().empty());
}

// A delayed frame whose receiver has gone is simply not delivered.
TEST_F(Faults, ADelayedFrameForADetachedPortIsDiscarded) {
  stage().Add({.receivers = {pb}, .action = RuleAction::kDelay, .delay = 5ms});
  broker.Submit(pa, Frame("181#01"));
  s.Advance(1ms);
  EXPECT_TRUE(broker.Detach(pb));
  s.Advance(10ms);
  EXPECT_TRUE(b.frames.empty());
  EXPECT_EQ(c.Ids(), (std::vector<std::string>{"181#01"}));
}

}  // namespace
}  // namespace canfleet::broker
