// Node guarding / life guarding, slave side: CiA 301 v4.2 §7.2.8.3.2.1 (node guarding protocol:
// RTR on 700h+id, reply DLC 1 = toggle bit 7 | state), §7.5.2.11 (100Ch guard time, ms, 0 disables
// life guarding), §7.5.2.12 (100Dh life time factor, 0 disables life guarding). Facts sheet §5.
#include "node/canopen/guarding/node_guarding.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "bus/loopback_bus.hpp"
#include "tests/support/bus_probe.hpp"

namespace canfleet::canopen {
namespace {

using namespace std::chrono_literals;
using Frames = std::vector<std::string>;
using Calls = std::vector<std::string>;

/// Records OnCommError calls as "life-guard <id> on|off".
class RecordingSink final : public CommErrorSink {
 public:
  void OnCommError(const CommError& error, bool active) override {
    char text[40];
    std::snprintf(text, sizeof text, "%s %02X %s",
                  error.kind == CommErrorKind::kLifeGuardTimeout ? "life-guard" : "other", error.detail,
                  active ? "on" : "off");
    calls.emplace_back(text);
  }
  Calls Take() {
    auto out = std::move(calls);
    calls.clear();
    return out;
  }
  Calls calls;
};

class NodeGuardingTest : public ::testing::Test {
 protected:
  NodeGuardingTest() {
    guarding.SetNodeId(0x0B);
    port.OnReceive([this](const CanFrame& frame, BusTime) { consumed.push_back(guarding.OnFrame(frame)); });
  }

  void Configure(std::uint16_t guard_time_ms, std::uint8_t factor) {
    ASSERT_EQ(od.Write(0x100C, 0, EncodeLe<std::uint16_t>(guard_time_ms)), SdoAbort::kNone);
    ASSERT_EQ(od.Write(0x100D, 0, Bytes{factor}), SdoAbort::kNone);
  }

  ObjectDictionary od = [] {
    ObjectDictionary d;
    AddGuardingObjects(d);
    d.AddVar(0x1017, "Producer heartbeat time", DataType::kUnsigned16, Access::kRw,
             EncodeLe<std::uint16_t>(0));
    return d;
  }();
  SimulatedScheduler scheduler;
  LoopbackBus bus;
  test::BusProbe master{bus, "master"};
  LoopbackPort& port = bus.Attach("node");
  RecordingSink sink;
  NmtState state = NmtState::kPreOperational;
  NodeGuarding guarding{od, port, scheduler, sink, [this] { return state; }};
  std::vector<bool> consumed;
};

// §7.2.8.3.2.1: the toggle bit of the first reply is 0 and alternates with every reply; bits 6-0
// carry the NMT state (04h stopped, 05h operational, 7Fh pre-operational).
TEST_F(NodeGuardingTest, RepliesAlternateTheToggleBitAndCarryTheState) {
  for (int i = 0; i < 4; ++i)
    master.Send("70B#R1");
  state = NmtState::kOperational;
  master.Send("70B#R1");
  master.Send("70B#R1");
  state = NmtState::kStopped;
  master.Send("70B#R1");
  master.Send("70B#R1");
  EXPECT_EQ(master.Take(),
            (Frames{"70B#7F", "70B#FF", "70B#7F", "70B#FF", "70B#05", "70B#85", "70B#04", "70B#84"}));
  EXPECT_EQ(consumed, std::vector<bool>(8, true));
}

// Reset communication sets the toggle back to 0.
TEST_F(NodeGuardingTest, ResetRestartsTheToggleAtZero) {
  master.Send("70B#R1");
  guarding.Reset();
  master.Send("70B#R1");
  master.Send("70B#R1");
  EXPECT_EQ(master.Take(), (Frames{"70B#7F", "70B#7F", "70B#FF"}));
}

// Masters differ in the DLC of the request (python-canopen sends DLC 0): every RTR is answered
// with the one-byte reply.
TEST_F(NodeGuardingTest, RequestsWithAnyDlcAreAnswered) {
  master.Send("70B#R");
  master.Send("70B#R8");
  EXPECT_EQ(master.Take(), (Frames{"70B#7F", "70B#FF"}));
}

// Only a remote frame on 700h + own node-ID is a guard request.
TEST_F(NodeGuardingTest, OtherFramesAreNotGuardRequests) {
  for (const char* frame : {"70C#R1", "70A#R1", "70B#7F", "0000070B#R1", "60B#R1"})
    master.Send(frame);
  EXPECT_EQ(master.Count(), 0u);
  EXPECT_EQ(consumed, std::vector<bool>(5, false));
}

// Before boot-up and during a reset (Initialising) the node does not answer.
TEST_F(NodeGuardingTest, NoReplyWhileInitialising) {
  state = NmtState::kInitialising;
  master.Send("70B#R1");
  EXPECT_EQ(master.Count(), 0u);
  state = NmtState::kPreOperational;
  master.Send("70B#R1");
  EXPECT_EQ(master.Take(), Frames{"70B#7F"});  // the first reply still has toggle 0
}

TEST_F(NodeGuardingTest, NodeIdSelectsTheCobId) {
  guarding.SetNodeId(0);
  master.Send("700#R1");
  EXPECT_EQ(master.Count(), 0u);
  guarding.SetNodeId(127);
  master.Send("77F#R1");
  master.Send("70B#R1");
  EXPECT_EQ(master.Take(), Frames{"77F#7F"});
}

// Facts sheet §5: life guarding starts at the first RTR; life time = guard time × factor. No error
// at life time − 1 ms, the error at life time exactly, reported once.
TEST_F(NodeGuardingTest, LifeTimeExpiryIsExactAndReportedOnce) {
  Configure(100, 3);
  scheduler.Advance(10s);  // not started: no request yet
  EXPECT_TRUE(sink.calls.empty());
  master.Send("70B#R1");
  EXPECT_TRUE(guarding.LifeGuarding());
  EXPECT_EQ(guarding.LifeTime(), 300ms);
  scheduler.Advance(299ms);
  EXPECT_TRUE(sink.calls.empty());
  scheduler.Advance(1ms);
  EXPECT_EQ(sink.Take(), Calls{"life-guard 0B on"});
  scheduler.Advance(10s);
  EXPECT_TRUE(sink.calls.empty());
}

// Each request restarts the life time.
TEST_F(NodeGuardingTest, RequestsWithinTheLifeTimeKeepTheNodeAlive) {
  Configure(100, 3);
  for (int i = 0; i < 20; ++i) {
    master.Send("70B#R1");
    scheduler.Advance(299ms);
  }
  EXPECT_TRUE(sink.calls.empty());
  scheduler.Advance(1ms);
  EXPECT_EQ(sink.Take(), Calls{"life-guard 0B on"});
}

// The next request clears the error (and is answered); life guarding goes on.
TEST_F(NodeGuardingTest, NextRequestClearsTheLifeGuardError) {
  Configure(50, 2);
  master.Send("70B#R1");
  scheduler.Advance(100ms);
  EXPECT_EQ(sink.Take(), Calls{"life-guard 0B on"});
  master.Send("70B#R1");
  EXPECT_EQ(sink.Take(), Calls{"life-guard 0B off"});
  EXPECT_EQ(master.Take(), (Frames{"70B#7F", "70B#FF"}));
  scheduler.Advance(99ms);
  EXPECT_TRUE(sink.calls.empty());
  scheduler.Advance(1ms);
  EXPECT_EQ(sink.Take(), Calls{"life-guard 0B on"});
}

// §7.5.2.11/§7.5.2.12: guard time 0 or life time factor 0 disables life guarding; the requests
// are still answered.
TEST_F(NodeGuardingTest, LifeGuardingIsOffWhenGuardTimeOrFactorIsZero) {
  for (auto [guard_time, factor] : {std::pair<std::uint16_t, std::uint8_t>{0, 3}, {100, 0}, {0, 0}}) {
    Configure(guard_time, factor);
    master.Send("70B#R1");
    EXPECT_FALSE(guarding.LifeGuarding());
    scheduler.Advance(10s);
  }
  EXPECT_TRUE(sink.calls.empty());
  EXPECT_EQ(master.Take(), (Frames{"70B#7F", "70B#FF", "70B#7F"}));
  EXPECT_EQ(scheduler.ArmedCount(), 0u);
}

// CiA 301 §7.2.8.3.2: a device uses heartbeat or life guarding. With 1017h ≠ 0 heartbeat wins:
// no life guarding, but guard requests are still answered (our choice: harmless for the master).
TEST_F(NodeGuardingTest, HeartbeatConfiguredSwitchesLifeGuardingOff) {
  Configure(100, 3);
  ASSERT_EQ(od.Write(0x1017, 0, EncodeLe<std::uint16_t>(1000)), SdoAbort::kNone);
  master.Send("70B#R1");
  scheduler.Advance(10s);
  EXPECT_TRUE(sink.calls.empty());
  EXPECT_EQ(master.Take(), Frames{"70B#7F"});
  EXPECT_EQ(guarding.LifeTime(), Duration::zero());
}

// Turning heartbeat on while the life guard error is active: life guarding stops, the error clears.
TEST_F(NodeGuardingTest, SwitchingToHeartbeatClearsAPendingLifeGuardError) {
  Configure(100, 3);
  master.Send("70B#R1");
  scheduler.Advance(300ms);
  EXPECT_EQ(sink.Take(), Calls{"life-guard 0B on"});
  ASSERT_EQ(od.Write(0x1017, 0, EncodeLe<std::uint16_t>(1000)), SdoAbort::kNone);
  EXPECT_EQ(sink.Take(), Calls{"life-guard 0B off"});
  EXPECT_FALSE(guarding.LifeGuarding());
}

// A new guard time or factor applies at once: the running life time restarts from the write.
TEST_F(NodeGuardingTest, ConfigurationChangeRestartsTheLifeTime) {
  Configure(100, 3);
  master.Send("70B#R1");
  scheduler.Advance(200ms);
  ASSERT_EQ(od.Write(0x100D, 0, Bytes{5}), SdoAbort::kNone);  // life time 500 ms from now
  scheduler.Advance(499ms);
  EXPECT_TRUE(sink.calls.empty());
  scheduler.Advance(1ms);
  EXPECT_EQ(sink.Take(), Calls{"life-guard 0B on"});
  // Switching off clears the pending error.
  ASSERT_EQ(od.Write(0x100C, 0, EncodeLe<std::uint16_t>(0)), SdoAbort::kNone);
  EXPECT_EQ(sink.Take(), Calls{"life-guard 0B off"});
}

// Reset communication: life guarding waits for the first request again, a pending error clears
// with the node-ID it was raised with (the stack may set a new node-ID before the reset).
TEST_F(NodeGuardingTest, ResetStopsLifeGuardingAndClearsTheError) {
  Configure(100, 3);
  master.Send("70B#R1");
  scheduler.Advance(300ms);
  EXPECT_EQ(sink.Take(), Calls{"life-guard 0B on"});
  guarding.SetNodeId(0x0C);
  guarding.Reset();
  EXPECT_EQ(sink.Take(), Calls{"life-guard 0B off"});
  EXPECT_FALSE(guarding.LifeGuarding());
  scheduler.Advance(10s);
  EXPECT_TRUE(sink.calls.empty());
  master.Send("70C#R1");
  scheduler.Advance(300ms);
  EXPECT_EQ(sink.Take(), Calls{"life-guard 0C on"});
}

// 100Ch/100Dh are optional (the encoder has neither): no life guarding, requests still answered.
TEST(NodeGuardingWithoutObjects, ToleratesMissingObjects) {
  ObjectDictionary od;
  SimulatedScheduler scheduler;
  LoopbackBus bus;
  test::BusProbe master{bus, "master"};
  LoopbackPort& port = bus.Attach("node");
  RecordingSink sink;
  NodeGuarding guarding{od, port, scheduler, sink, [] { return NmtState::kOperational; }};
  guarding.SetNodeId(1);
  EXPECT_TRUE(guarding.OnFrame(test::Frame("701#R1")));
  scheduler.Advance(10s);
  EXPECT_EQ(master.Take(), Frames{"701#05"});
  EXPECT_TRUE(sink.calls.empty());
}

TEST(GuardingObjects, AddGuardingObjectsCreatesTheStandardObjects) {
  ObjectDictionary od;
  AddGuardingObjects(od);
  ASSERT_NE(od.Find(0x100C, 0), nullptr);
  ASSERT_NE(od.Find(0x100D, 0), nullptr);
  EXPECT_EQ(od.Find(0x100C, 0)->type, DataType::kUnsigned16);
  EXPECT_EQ(od.Find(0x100D, 0)->type, DataType::kUnsigned8);
  EXPECT_EQ(od.Find(0x100C, 0)->access, Access::kRw);
  EXPECT_EQ(od.GetUnsigned(0x100C, 0), 0u);
  EXPECT_EQ(od.GetUnsigned(0x100D, 0), 0u);
}

}  // namespace
}  // namespace canfleet::canopen
