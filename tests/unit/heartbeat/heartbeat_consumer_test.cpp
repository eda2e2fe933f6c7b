// Heartbeat consumer, CiA 301 v4.2 §7.2.8.3.2.2 (heartbeat protocol) and §7.5.2.19 (1016h consumer
// heartbeat time: bits 23-16 node-ID, bits 15-0 time in ms). Facts sheet §5 (CANopenNode, Lely).
#include "node/canopen/heartbeat/heartbeat_consumer.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "bus/loopback_bus.hpp"
#include "tests/support/allocation_counter.hpp"
#include "tests/support/bus_probe.hpp"
#include "tests/unit/heartbeat/heartbeat_test_support.hpp"

namespace canfleet::canopen {
namespace {

using namespace std::chrono_literals;
using Calls = std::vector<std::string>;
using State = HeartbeatConsumerStatus::State;

std::uint32_t Entry(std::uint8_t node_id, std::uint16_t time_ms) {
  return std::uint32_t{node_id} << 16 | time_ms;
}

class HeartbeatConsumerTest : public ::testing::Test {
 protected:
  HeartbeatConsumerTest() {
    port.OnReceive([this](const CanFrame& frame, BusTime) { EXPECT_FALSE(consumer->OnFrame(frame)); });
  }

  /// Builds the consumer after the test configured 1016h (as the stack does after loading the EDS).
  void Create() { consumer = std::make_unique<HeartbeatConsumer>(od, scheduler, sink); }

  SdoAbort Write(std::uint8_t sub, std::uint32_t value) {
    return od.Write(0x1016, sub, EncodeLe<std::uint32_t>(value));
  }

  State StateOf(std::size_t entry) const { return consumer->Status().at(entry).state; }

  ObjectDictionary od = [] {
    ObjectDictionary d;
    AddHeartbeatObjects(d, 4);  // the Quad controller and the valve block have 4 entries
    return d;
  }();
  SimulatedScheduler scheduler;
  LoopbackBus bus;
  test::BusProbe net{bus, "net"};  // the other nodes and the master
  LoopbackPort& port = bus.Attach("node");
  test::RecordingSink sink;
  std::unique_ptr<HeartbeatConsumer> consumer;
};

// Device digests: "monitoring starts at the first heartbeat received" (CANopenNode CO_HBconsumer).
TEST_F(HeartbeatConsumerTest, MonitoringStartsAtTheFirstHeartbeat) {
  ASSERT_EQ(Write(1, Entry(0x20, 100)), SdoAbort::kNone);
  Create();
  EXPECT_EQ(StateOf(0), State::kWaiting);
  scheduler.Advance(10s);
  EXPECT_TRUE(sink.Empty());
  net.Send("720#05");
  EXPECT_EQ(StateOf(0), State::kActive);
  scheduler.Advance(100ms);
  EXPECT_EQ(sink.Take(), Calls{"hb-timeout 20 on"});
}

// A boot-up (state 00h) is not a heartbeat: it does not start monitoring.
TEST_F(HeartbeatConsumerTest, BootUpDoesNotStartMonitoring) {
  Create();
  ASSERT_EQ(Write(1, Entry(0x20, 100)), SdoAbort::kNone);
  net.Send("720#00");
  EXPECT_EQ(StateOf(0), State::kWaiting);
  EXPECT_EQ(consumer->Status().at(0).last_state, NmtState::kInitialising);
  scheduler.Advance(1s);
  EXPECT_TRUE(sink.Empty());
}

// The consumer time is measured from the last heartbeat: nothing at t = time − 1 ms, the timeout
// at t = time exactly, and only once however long the silence lasts.
TEST_F(HeartbeatConsumerTest, TimeoutIsExactAndReportedOnce) {
  Create();
  ASSERT_EQ(Write(2, Entry(0x33, 250)), SdoAbort::kNone);
  scheduler.Advance(17ms);
  net.Send("733#7F");
  scheduler.Advance(249ms);
  EXPECT_TRUE(sink.Empty());
  EXPECT_EQ(StateOf(1), State::kActive);
  scheduler.Advance(1ms);
  EXPECT_EQ(sink.Take(), Calls{"hb-timeout 33 on"});
  EXPECT_EQ(StateOf(1), State::kTimedOut);
  scheduler.Advance(10s);
  EXPECT_TRUE(sink.Empty());
}

// Each heartbeat restarts the consumer time: heartbeats 1 ms inside the time never time out.
TEST_F(HeartbeatConsumerTest, EachHeartbeatRestartsTheConsumerTime) {
  Create();
  ASSERT_EQ(Write(1, Entry(0x20, 100)), SdoAbort::kNone);
  for (int i = 0; i < 50; ++i) {
    net.Send("720#05");
    scheduler.Advance(99ms);
  }
  EXPECT_TRUE(sink.Empty());
  scheduler.Advance(1ms);
  EXPECT_EQ(sink.Take(), Calls{"hb-timeout 20 on"});
}

// When heartbeats return the error goes away, and monitoring goes on (a new silence reports again).
TEST_F(HeartbeatConsumerTest, RecoveryClearsTheErrorAndMonitoringContinues) {
  Create();
  ASSERT_EQ(Write(1, Entry(0x20, 100)), SdoAbort::kNone);
  net.Send("720#05");
  scheduler.Advance(500ms);
  EXPECT_EQ(sink.Take(), Calls{"hb-timeout 20 on"});
  net.Send("720#04");
  EXPECT_EQ(sink.Take(), Calls{"hb-timeout 20 off"});
  EXPECT_EQ(StateOf(0), State::kActive);
  EXPECT_EQ(consumer->Status().at(0).last_state, NmtState::kStopped);
  net.Send("720#04");
  EXPECT_TRUE(sink.Empty());  // "off" only once
  scheduler.Advance(99ms);
  EXPECT_TRUE(sink.Empty());
  scheduler.Advance(1ms);
  EXPECT_EQ(sink.Take(), Calls{"hb-timeout 20 on"});
}

// A boot-up from a node being monitored means it was reset: an event (on, then off), and the
// entry waits for the first heartbeat again (no timeout while the node boots).
TEST_F(HeartbeatConsumerTest, BootUpOfAnActiveNodeIsReportedAndMonitoringWaitsAgain) {
  Create();
  ASSERT_EQ(Write(1, Entry(0x20, 100)), SdoAbort::kNone);
  net.Send("720#05");
  scheduler.Advance(50ms);
  net.Send("720#00");
  EXPECT_EQ(sink.Take(), (Calls{"boot-up 20 on", "boot-up 20 off"}));
  EXPECT_EQ(StateOf(0), State::kWaiting);
  scheduler.Advance(10s);
  EXPECT_TRUE(sink.Empty());
  net.Send("720#00");  // a second boot-up while waiting is no event
  EXPECT_TRUE(sink.Empty());
  net.Send("720#7F");
  EXPECT_EQ(StateOf(0), State::kActive);
  scheduler.Advance(100ms);
  EXPECT_EQ(sink.Take(), Calls{"hb-timeout 20 on"});
}

// A timed-out node that boots is alive again: its timeout clears, then the boot-up is reported.
TEST_F(HeartbeatConsumerTest, BootUpOfATimedOutNodeClearsTheTimeout) {
  Create();
  ASSERT_EQ(Write(1, Entry(0x20, 100)), SdoAbort::kNone);
  net.Send("720#05");
  scheduler.Advance(100ms);
  EXPECT_EQ(sink.Take(), Calls{"hb-timeout 20 on"});
  net.Send("720#00");
  EXPECT_EQ(sink.Take(), (Calls{"hb-timeout 20 off", "boot-up 20 on", "boot-up 20 off"}));
  EXPECT_EQ(StateOf(0), State::kWaiting);
}

// §7.5.2.19: one active entry per node-ID. A second active entry for the same node is refused with
// 06040043h (general parameter incompatibility) and the old value stays.
TEST_F(HeartbeatConsumerTest, DuplicateNodeIdIsRefused) {
  Create();
  ASSERT_EQ(Write(1, Entry(0x20, 100)), SdoAbort::kNone);
  EXPECT_EQ(Write(3, Entry(0x20, 500)), SdoAbort::kParameterIncompatible);
  EXPECT_EQ(static_cast<std::uint32_t>(SdoAbort::kParameterIncompatible), 0x06040043u);
  EXPECT_EQ(od.GetUnsigned(0x1016, 3), 0u);
  EXPECT_EQ(StateOf(2), State::kUnconfigured);
  // Not a conflict: the same entry rewritten, an inactive entry (time 0 or node-ID 0) for that node.
  EXPECT_EQ(Write(1, Entry(0x20, 200)), SdoAbort::kNone);
  EXPECT_EQ(Write(3, Entry(0x20, 0)), SdoAbort::kNone);
  EXPECT_EQ(Write(4, Entry(0x00, 100)), SdoAbort::kNone);
  // Once the first entry is disabled, the node-ID is free again.
  EXPECT_EQ(Write(1, 0), SdoAbort::kNone);
  EXPECT_EQ(Write(3, Entry(0x20, 500)), SdoAbort::kNone);
  EXPECT_EQ(StateOf(2), State::kWaiting);
}

// The device itself bypasses validators (Origin::kDevice): a duplicate then stays with the first
// entry, so a node is never monitored (and reported) twice.
TEST_F(HeartbeatConsumerTest, DuplicateWrittenByTheDeviceIsMonitoredOnce) {
  ASSERT_EQ(od.SetUnsigned(0x1016, 1, Entry(0x20, 100)), SdoAbort::kNone);
  ASSERT_EQ(od.SetUnsigned(0x1016, 2, Entry(0x20, 100)), SdoAbort::kNone);
  Create();
  EXPECT_EQ(StateOf(0), State::kWaiting);
  EXPECT_EQ(StateOf(1), State::kUnconfigured);
  net.Send("720#05");
  scheduler.Advance(100ms);
  EXPECT_EQ(sink.Take(), Calls{"hb-timeout 20 on"});
}

// §7.5.2.19: sub0 (number of entries) is read-only, 06010002h; also when an EDS declared it rw.
TEST_F(HeartbeatConsumerTest, Sub0IsReadOnly) {
  Create();
  EXPECT_EQ(od.Write(0x1016, 0, Bytes{2}), SdoAbort::kReadOnly);
  od.Find(0x1016, 0)->access = Access::kRw;
  EXPECT_EQ(od.Write(0x1016, 0, Bytes{2}), SdoAbort::kReadOnly);
  EXPECT_EQ(od.GetUnsigned(0x1016, 0), 4u);
}

// An entry is active only with node-ID 1..127 and time ≠ 0 (CANopenNode, Lely).
TEST_F(HeartbeatConsumerTest, EntriesWithoutNodeIdOrTimeAreUnconfigured) {
  Create();
  ASSERT_EQ(Write(1, Entry(0x20, 0)), SdoAbort::kNone);
  ASSERT_EQ(Write(2, Entry(0x00, 100)), SdoAbort::kNone);
  ASSERT_EQ(Write(3, Entry(0x80, 100)), SdoAbort::kNone);
  ASSERT_EQ(Write(4, Entry(0xFF, 100)), SdoAbort::kNone);
  for (std::size_t i = 0; i < 4; ++i)
    EXPECT_EQ(StateOf(i), State::kUnconfigured) << i;
  net.Send("720#05");
  net.Send("77F#05");
  scheduler.Advance(10s);
  EXPECT_TRUE(sink.Empty());
  EXPECT_EQ(scheduler.ArmedCount(), 0u);
}

// Entries are independent: each has its own time, its own node, its own error.
TEST_F(HeartbeatConsumerTest, MultipleEntriesAreIndependent) {
  Create();
  ASSERT_EQ(Write(1, Entry(0x20, 100)), SdoAbort::kNone);
  ASSERT_EQ(Write(2, Entry(0x21, 250)), SdoAbort::kNone);
  ASSERT_EQ(Write(4, Entry(0x7F, 1000)), SdoAbort::kNone);
  net.Send("720#05");
  net.Send("721#05");
  net.Send("77F#05");
  scheduler.Advance(60ms);
  net.Send("721#05");  // keeps 0x21 alive, not 0x20
  scheduler.Advance(40ms);
  EXPECT_EQ(sink.Take(), Calls{"hb-timeout 20 on"});
  EXPECT_EQ(StateOf(1), State::kActive);
  scheduler.Advance(210ms);
  EXPECT_EQ(sink.Take(), Calls{"hb-timeout 21 on"});
  net.Send("720#05");
  EXPECT_EQ(sink.Take(), Calls{"hb-timeout 20 off"});
  EXPECT_EQ(StateOf(1), State::kTimedOut);
  scheduler.Advance(690ms);  // 0x20 goes silent again at 410 ms, 0x7F at 1000 ms
  EXPECT_EQ(sink.Take(), (Calls{"hb-timeout 20 on", "hb-timeout 7F on"}));
  EXPECT_EQ(StateOf(2), State::kUnconfigured);
}

// Writing an entry restarts its monitoring (back to waiting); the other entries keep running.
TEST_F(HeartbeatConsumerTest, ChangingAnEntryRestartsOnlyThatEntry) {
  Create();
  ASSERT_EQ(Write(1, Entry(0x20, 100)), SdoAbort::kNone);
  ASSERT_EQ(Write(2, Entry(0x21, 100)), SdoAbort::kNone);
  net.Send("720#05");
  net.Send("721#05");
  scheduler.Advance(50ms);
  ASSERT_EQ(Write(1, Entry(0x20, 300)), SdoAbort::kNone);
  EXPECT_EQ(StateOf(0), State::kWaiting);
  EXPECT_EQ(consumer->Status().at(0).period, 300ms);
  scheduler.Advance(50ms);
  EXPECT_EQ(sink.Take(), Calls{"hb-timeout 21 on"});  // entry 2 kept its timer
  scheduler.Advance(1s);
  EXPECT_TRUE(sink.Empty());  // entry 1 waits for its first heartbeat
  net.Send("720#05");
  scheduler.Advance(300ms);
  EXPECT_EQ(sink.Take(), Calls{"hb-timeout 20 on"});
}

// Any write of the entry counts as a change, even with the same value (as CANopenNode re-initialises
// the entry on every 1016h download): a timed-out entry is cleared and waits again.
TEST_F(HeartbeatConsumerTest, RewritingTheSameValueRestartsTheEntry) {
  Create();
  ASSERT_EQ(Write(1, Entry(0x20, 100)), SdoAbort::kNone);
  net.Send("720#05");
  scheduler.Advance(100ms);
  EXPECT_EQ(sink.Take(), Calls{"hb-timeout 20 on"});
  ASSERT_EQ(Write(1, Entry(0x20, 100)), SdoAbort::kNone);
  EXPECT_EQ(sink.Take(), Calls{"hb-timeout 20 off"});
  EXPECT_EQ(StateOf(0), State::kWaiting);
}

// Moving an entry to another node: the old node's heartbeats no longer count, and a pending timeout
// of the old node is cleared (nobody monitors it any more).
TEST_F(HeartbeatConsumerTest, ReconfiguringATimedOutEntryClearsItsError) {
  Create();
  ASSERT_EQ(Write(1, Entry(0x20, 100)), SdoAbort::kNone);
  net.Send("720#05");
  scheduler.Advance(100ms);
  EXPECT_EQ(sink.Take(), Calls{"hb-timeout 20 on"});
  ASSERT_EQ(Write(1, Entry(0x22, 100)), SdoAbort::kNone);
  EXPECT_EQ(sink.Take(), Calls{"hb-timeout 20 off"});
  net.Send("720#05");
  EXPECT_EQ(StateOf(0), State::kWaiting);
  scheduler.Advance(1s);
  EXPECT_TRUE(sink.Empty());
  ASSERT_EQ(Write(1, 0), SdoAbort::kNone);  // disabling an idle entry reports nothing
  EXPECT_TRUE(sink.Empty());
}

// Reset communication restarts monitoring: every entry waits again, timeouts are cleared.
TEST_F(HeartbeatConsumerTest, ResetPutsEveryEntryBackToWaiting) {
  Create();
  ASSERT_EQ(Write(1, Entry(0x20, 100)), SdoAbort::kNone);
  ASSERT_EQ(Write(2, Entry(0x21, 300)), SdoAbort::kNone);
  net.Send("720#05");
  net.Send("721#05");
  scheduler.Advance(100ms);
  EXPECT_EQ(sink.Take(), Calls{"hb-timeout 20 on"});
  consumer->Reset();
  EXPECT_EQ(sink.Take(), Calls{"hb-timeout 20 off"});
  EXPECT_EQ(StateOf(0), State::kWaiting);
  EXPECT_EQ(StateOf(1), State::kWaiting);
  scheduler.Advance(10s);
  EXPECT_TRUE(sink.Empty());
}

// Facts sheet §5 (CANopenNode): a heartbeat has DLC 1; other lengths, remote frames and 29-bit
// frames are ignored. Frames are never consumed.
TEST_F(HeartbeatConsumerTest, OnlyDataFramesWithDlcOneCount) {
  Create();
  ASSERT_EQ(Write(1, Entry(0x20, 100)), SdoAbort::kNone);
  for (const char* frame : {"720#", "720#0500", "720#R1", "720#R", "00000720#05", "620#05", "7A0#05"}) {
    net.Send(frame);
  }
  EXPECT_EQ(StateOf(0), State::kWaiting);
  scheduler.Advance(1s);
  EXPECT_TRUE(sink.Empty());
}

// Heartbeats of nodes nobody monitors change nothing.
TEST_F(HeartbeatConsumerTest, UnmonitoredNodesAreIgnored) {
  Create();
  ASSERT_EQ(Write(1, Entry(0x20, 100)), SdoAbort::kNone);
  net.Send("721#05");
  net.Send("701#05");
  EXPECT_EQ(StateOf(0), State::kWaiting);
  EXPECT_EQ(scheduler.ArmedCount(), 0u);
}

TEST_F(HeartbeatConsumerTest, StatusDescribesEveryEntry) {
  Create();
  ASSERT_EQ(Write(2, Entry(0x21, 0x1234)), SdoAbort::kNone);
  net.Send("721#7F");
  auto status = consumer->Status();
  ASSERT_EQ(status.size(), 4u);
  EXPECT_EQ(status[0].sub_index, 1);
  EXPECT_EQ(status[0].state, State::kUnconfigured);
  EXPECT_EQ(status[1].sub_index, 2);
  EXPECT_EQ(status[1].node_id, 0x21);
  EXPECT_EQ(status[1].period, 0x1234ms);
  EXPECT_EQ(status[1].state, State::kActive);
  EXPECT_EQ(status[1].last_state, NmtState::kPreOperational);
}

// Restoring defaults (reset communication) runs the listeners: entries follow the OD.
TEST_F(HeartbeatConsumerTest, RestoredDefaultsApply) {
  Create();
  ASSERT_EQ(Write(1, Entry(0x20, 100)), SdoAbort::kNone);
  net.Send("720#05");
  od.RestoreDefaults(0x1000, 0x1FFF, 5);
  EXPECT_EQ(StateOf(0), State::kUnconfigured);
  scheduler.Advance(1s);
  EXPECT_TRUE(sink.Empty());
}

// 1016h is optional: without it the consumer does nothing.
TEST(HeartbeatConsumerWithoutObject, ToleratesMissing1016) {
  ObjectDictionary od;
  SimulatedScheduler scheduler;
  test::RecordingSink sink;
  HeartbeatConsumer consumer(od, scheduler, sink);
  EXPECT_FALSE(consumer.OnFrame(canfleet::test::Frame("720#05")));
  EXPECT_TRUE(consumer.Status().empty());
}

// The consumer path (heartbeat, timeout, recovery, boot-up) allocates nothing per frame.
class CountingSink final : public CommErrorSink {
 public:
  void OnCommError(const CommError&, bool) override { ++calls; }
  int calls = 0;
};

TEST(HeartbeatConsumerAllocation, FramePathDoesNotAllocate) {
  ObjectDictionary od;
  AddHeartbeatObjects(od, 127);
  for (std::uint8_t sub = 1; sub <= 127; ++sub) {
    ASSERT_EQ(od.Write(0x1016, sub, EncodeLe<std::uint32_t>(Entry(sub, 100))), SdoAbort::kNone);
  }
  SimulatedScheduler scheduler;
  CountingSink sink;
  HeartbeatConsumer consumer(od, scheduler, sink);
  const CanFrame heartbeat = canfleet::test::Frame("740#05");
  const CanFrame boot_up = canfleet::test::Frame("740#00");
  const CanFrame other = canfleet::test::Frame("741#7F");
  auto round = [&] {
    consumer.OnFrame(heartbeat);
    consumer.OnFrame(other);
    scheduler.Advance(150ms);  // both time out
    consumer.OnFrame(heartbeat);
    consumer.OnFrame(boot_up);
  };
  round();  // the scheduler's timer heap grows once to hold both timers
  const auto before = canfleet::test::AllocationCount();
  for (int i = 0; i < 100; ++i)
    round();
  EXPECT_EQ(canfleet::test::AllocationCount(), before);
  // First round: 2 timeouts on, 0x40 off, boot-up on/off; later rounds also 0x41 off.
  EXPECT_EQ(sink.calls, 5 + 100 * 6);
}

}  // namespace
}  // namespace canfleet::canopen
