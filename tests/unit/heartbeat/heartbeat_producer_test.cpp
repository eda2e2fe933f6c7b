// Heartbeat producer, CiA 301 v4.2 §7.2.8.3.2.2 (heartbeat protocol) and §7.5.2.20 (1017h
// producer heartbeat time, ms, 0 = off). Frame: 700h + node-ID, DLC 1, byte 0 = NMT state.
#include "node/canopen/heartbeat/heartbeat_producer.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "bus/loopback_bus.hpp"
#include "tests/support/bus_probe.hpp"
#include "tests/unit/heartbeat/heartbeat_test_support.hpp"

namespace canfleet::canopen {
namespace {

using namespace std::chrono_literals;
using Frames = std::vector<std::string>;

class HeartbeatProducerTest : public ::testing::Test {
 protected:
  HeartbeatProducerTest() { producer.SetNodeId(0x0A); }

  void SetPeriod(std::uint16_t ms) {
    ASSERT_EQ(od.Write(0x1017, 0, EncodeLe<std::uint16_t>(ms)), SdoAbort::kNone);
  }

  // The objects exist before the service is built (services hook the objects they find).
  ObjectDictionary od = [] {
    ObjectDictionary d;
    AddHeartbeatObjects(d, 0);
    return d;
  }();
  SimulatedScheduler scheduler;
  LoopbackBus bus;
  test::TimedLog log{bus, scheduler};
  LoopbackPort& port = bus.Attach("node");
  NmtState state = NmtState::kPreOperational;
  HeartbeatProducer producer{od, port, scheduler, [this] { return state; }};
};

// The boot-up frame counts as the first heartbeat: the next one is due one period after Start().
TEST_F(HeartbeatProducerTest, FirstHeartbeatOnePeriodAfterStartThenEveryPeriod) {
  SetPeriod(100);
  producer.Start();
  scheduler.Advance(99ms);
  EXPECT_EQ(log.Take(), Frames{});
  scheduler.Advance(1ms);
  EXPECT_EQ(log.Take(), Frames{"100 70A#7F"});
  scheduler.Advance(300ms);
  EXPECT_EQ(log.Take(), (Frames{"200 70A#7F", "300 70A#7F", "400 70A#7F"}));
}

// Each deadline is the previous deadline + period, however the clock is driven: no drift.
TEST_F(HeartbeatProducerTest, PeriodDoesNotDrift) {
  SetPeriod(30);
  producer.Start();
  for (int i = 0; i < 100; ++i)
    scheduler.Advance(7ms);  // 700 ms in steps that never hit a deadline
  auto frames = log.Take();
  ASSERT_EQ(frames.size(), 23u);
  EXPECT_EQ(frames.front(), "30 70A#7F");
  EXPECT_EQ(frames.back(), "690 70A#7F");
}

// §7.2.8.3.2.2, table of states: 04h stopped, 05h operational, 7Fh pre-operational; the heartbeat
// is produced in Stopped too (error control runs in every state after boot-up, §7.3.2 table 51).
TEST_F(HeartbeatProducerTest, StateByteFollowsTheNmtStateIncludingStopped) {
  SetPeriod(10);
  producer.Start();
  scheduler.Advance(10ms);
  state = NmtState::kOperational;
  scheduler.Advance(10ms);
  state = NmtState::kStopped;
  scheduler.Advance(10ms);
  state = NmtState::kPreOperational;
  scheduler.Advance(10ms);
  EXPECT_EQ(log.Take(), (Frames{"10 70A#7F", "20 70A#05", "30 70A#04", "40 70A#7F"}));
}

// §7.5.2.20: 1017h = 0 disables the heartbeat.
TEST_F(HeartbeatProducerTest, ZeroPeriodProducesNothing) {
  producer.Start();
  scheduler.Advance(10s);
  EXPECT_EQ(log.Take(), Frames{});
  EXPECT_EQ(scheduler.ArmedCount(), 0u);
}

// A new producer time applies at once: the next heartbeat is one new period after the write.
TEST_F(HeartbeatProducerTest, PeriodChangeRestartsTheTimer) {
  SetPeriod(100);
  producer.Start();
  scheduler.Advance(250ms);
  EXPECT_EQ(log.Take(), (Frames{"100 70A#7F", "200 70A#7F"}));
  SetPeriod(1000);
  scheduler.Advance(999ms);
  EXPECT_EQ(log.Take(), Frames{});
  scheduler.Advance(1ms);
  EXPECT_EQ(log.Take(), Frames{"1250 70A#7F"});
  SetPeriod(20);
  scheduler.Advance(40ms);
  EXPECT_EQ(log.Take(), (Frames{"1270 70A#7F", "1290 70A#7F"}));
}

TEST_F(HeartbeatProducerTest, WritingZeroStopsAndWritingAPeriodStartsAgain) {
  SetPeriod(100);
  producer.Start();
  scheduler.Advance(100ms);
  SetPeriod(0);
  scheduler.Advance(1s);
  EXPECT_EQ(log.Take(), Frames{"100 70A#7F"});
  SetPeriod(50);
  scheduler.Advance(100ms);
  EXPECT_EQ(log.Take(), (Frames{"1150 70A#7F", "1200 70A#7F"}));
}

// Before boot-up (not started) and after Stop() nothing is sent, even with 1017h set; a write of
// 1017h does not start a stopped producer.
TEST_F(HeartbeatProducerTest, NothingBeforeStartOrAfterStop) {
  SetPeriod(100);
  scheduler.Advance(1s);
  producer.Start();
  scheduler.Advance(100ms);
  producer.Stop();
  scheduler.Advance(1s);
  SetPeriod(10);
  scheduler.Advance(1s);
  EXPECT_EQ(log.Take(), Frames{"1100 70A#7F"});
  EXPECT_FALSE(producer.Running());
}

// During a reset the node is Initialising: its next frame is the boot-up, not a heartbeat.
TEST_F(HeartbeatProducerTest, NoHeartbeatWhileInitialising) {
  SetPeriod(100);
  producer.Start();
  state = NmtState::kInitialising;
  scheduler.Advance(200ms);
  state = NmtState::kPreOperational;
  scheduler.Advance(100ms);
  EXPECT_EQ(log.Take(), Frames{"300 70A#7F"});
}

TEST_F(HeartbeatProducerTest, NodeIdSelectsTheCobId) {
  SetPeriod(100);
  producer.SetNodeId(0);  // no valid node-ID: nothing to send
  producer.Start();
  scheduler.Advance(100ms);
  producer.SetNodeId(127);
  scheduler.Advance(100ms);
  EXPECT_EQ(log.Take(), Frames{"200 77F#7F"});
}

// A device without 1017h (optional object) simply has no heartbeat.
TEST(HeartbeatProducerWithoutObject, ToleratesMissing1017) {
  ObjectDictionary od;
  SimulatedScheduler scheduler;
  LoopbackBus bus;
  test::TimedLog log{bus, scheduler};
  HeartbeatProducer producer{od, bus.Attach("node"), scheduler, [] { return NmtState::kOperational; }};
  producer.SetNodeId(1);
  producer.Start();
  scheduler.Advance(10s);
  EXPECT_EQ(log.Take(), Frames{});
}

TEST(HeartbeatObjects, AddHeartbeatObjectsCreatesTheStandardObjects) {
  ObjectDictionary od;
  AddHeartbeatObjects(od, 3);
  const SubObject* producer_time = od.Find(0x1017, 0);
  ASSERT_NE(producer_time, nullptr);
  EXPECT_EQ(producer_time->type, DataType::kUnsigned16);
  EXPECT_EQ(producer_time->access, Access::kRw);
  EXPECT_EQ(od.GetUnsigned(0x1017, 0), 0u);
  const Object* consumer = od.Find(0x1016);
  ASSERT_NE(consumer, nullptr);
  EXPECT_EQ(consumer->code, ObjectCode::kArray);
  EXPECT_EQ(consumer->subs.size(), 4u);
  EXPECT_EQ(od.GetUnsigned(0x1016, 0), 3u);
  EXPECT_EQ(consumer->subs.at(0).access, Access::kRo);
  EXPECT_EQ(consumer->subs.at(3).type, DataType::kUnsigned32);
  EXPECT_EQ(od.GetUnsigned(0x1016, 3), 0u);

  ObjectDictionary no_consumer;
  AddHeartbeatObjects(no_consumer, 0);
  EXPECT_EQ(no_consumer.Find(0x1016), nullptr);
  EXPECT_NE(no_consumer.Find(0x1017), nullptr);
}

}  // namespace
}  // namespace canfleet::canopen
