// FleetView: the monitor's model and the events derived from status changes.
#include "tools/telemetry/fleet_view.hpp"

#include <gtest/gtest.h>

#include <algorithm>

namespace canfleet::tools {
namespace {

using namespace std::chrono_literals;
using telemetry::ControllerState;
using telemetry::HeartbeatConsumerState;
using telemetry::NmtState;

const WallTime kStart = WallTime(1'700'000'000s);

NodeStatusSample Status(std::uint8_t node, NmtState state = NmtState::kOperational) {
  NodeStatusSample s;
  s.bus = "can0";
  s.node_id = node;
  s.device = "quad";
  s.nmt_state = state;
  s.publish_period = 1s;
  return s;
}

SampleMeta At(WallTime time) {
  return {.source_time = time};
}

TEST(FleetView, FirstStatusIsSeenThenChangesAreEvents) {
  FleetView view(kStart);
  std::vector<FleetEvent> events;
  view.Apply(Status(5, NmtState::kPreOperational), At(kStart + 1s), &events);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, EventKind::kNodeSeen);
  events.clear();

  NodeStatusSample s = Status(5, NmtState::kOperational);
  s.controller_state = ControllerState::kErrorPassive;
  s.error_register = 0x11;
  view.Apply(s, At(kStart + 2s), &events);
  ASSERT_EQ(events.size(), 3u);
  EXPECT_EQ(events[0].kind, EventKind::kNmt);
  // The words of the CLI and the expectations (issue 29): vocabulary/nmt_state, bus/bus_port.
  EXPECT_EQ(events[0].from, "pre-operational");
  EXPECT_EQ(events[0].to, "operational");
  EXPECT_EQ(events[1].kind, EventKind::kController);
  EXPECT_EQ(events[1].to, "error-passive");
  EXPECT_EQ(events[2].kind, EventKind::kErrorRegister);
  EXPECT_EQ(events[2].from, "00h");
  EXPECT_EQ(events[2].to, "11h");
  EXPECT_EQ(view.nodes().at({"can0", 5}).last_change, kStart + 2s);
}

TEST(FleetView, AnUnchangedStatusIsNoEvent) {
  FleetView view(kStart);
  std::vector<FleetEvent> events;
  view.Apply(Status(1), At(kStart + 1s), nullptr);
  NodeStatusSample s = Status(1);
  s.rpdo_count = 100;
  view.Apply(s, At(kStart + 2s), &events);
  EXPECT_TRUE(events.empty());
  EXPECT_EQ(view.nodes().at({"can0", 1}).status.rpdo_count, 100u);
}

TEST(FleetView, HeartbeatConsumerTimeoutIsAnEventNamingThePeer) {
  FleetView view(kStart);
  NodeStatusSample s = Status(2);
  s.heartbeat_consumers = {{1, 250, HeartbeatConsumerState::kActive, NmtState::kOperational}};
  view.Apply(s, At(kStart + 1s), nullptr);
  s.heartbeat_consumers[0].state = HeartbeatConsumerState::kTimedOut;
  std::vector<FleetEvent> events;
  view.Apply(s, At(kStart + 2s), &events);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, EventKind::kHeartbeatConsumer);
  EXPECT_EQ(events[0].peer_node, 1);
  EXPECT_EQ(events[0].to, "timed-out");
  EXPECT_TRUE(IsFaulted(view.nodes().at({"can0", 2}), kStart + 2s));
}

TEST(FleetView, DisposeMeansGoneAndTheNextStatusMeansBack) {
  FleetView view(kStart);
  view.Apply(Status(3), At(kStart + 1s), nullptr);
  std::vector<FleetEvent> events;
  view.Apply(Status(3), {.source_time = kStart + 2s, .valid_data = false, .alive = false, .disposed = true},
             &events);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, EventKind::kNodeGone);
  EXPECT_EQ(events[0].to, "disposed");
  EXPECT_FALSE(view.nodes().at({"can0", 3}).alive);
  events.clear();
  view.Apply(Status(3), At(kStart + 3s), &events);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, EventKind::kNodeSeen);
  EXPECT_EQ(events[0].from, "gone");
}

// Issue 7's "node seen leaving" bug: a status whose instance was disposed before the reader took it
// arrives as valid data with the NOT_ALIVE_DISPOSED state, and no invalid sample follows.
TEST(FleetView, AValidSampleOfADisposedInstanceMeansGone) {
  FleetView view(kStart);
  view.Apply(Status(3), At(kStart + 1s), nullptr);
  std::vector<FleetEvent> events;
  view.Apply(Status(3, NmtState::kStopped),
             {.source_time = kStart + 2s, .valid_data = true, .alive = false, .disposed = true}, &events);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].kind, EventKind::kNmt);  // the last status is applied first
  EXPECT_EQ(events[1].kind, EventKind::kNodeGone);
  EXPECT_EQ(events[1].to, "disposed");
  const NodeRow& row = view.nodes().at({"can0", 3});
  EXPECT_FALSE(row.alive);
  EXPECT_TRUE(row.disposed);
  EXPECT_EQ(row.status.nmt_state, NmtState::kStopped);
}

// A late monitor whose first sample of a node is already without writers (the process died).
TEST(FleetView, AFirstSampleWithoutWritersIsSeenThenGone) {
  FleetView view(kStart);
  std::vector<FleetEvent> events;
  view.Apply(Status(4), {.source_time = kStart + 1s, .valid_data = true, .alive = false, .disposed = false},
             &events);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].kind, EventKind::kNodeSeen);
  EXPECT_EQ(events[1].kind, EventKind::kNodeGone);
  EXPECT_EQ(events[1].to, "no-writers");
  EXPECT_FALSE(view.nodes().at({"can0", 4}).alive);
}

TEST(FleetView, EventsOlderThanTheMonitorAreReplays) {
  FleetView view(kStart);
  std::vector<FleetEvent> events;
  EmcySample emcy{.bus = "can0", .node_id = 4, .emcy = {.code = 0x8130}};
  view.Apply(emcy, At(kStart - 5s), &events);
  view.Apply(emcy, At(kStart + 5s), &events);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_TRUE(events[0].replay);
  EXPECT_FALSE(events[1].replay);
}

TEST(FleetView, AnEmcyBeforeTheNodesFirstStatusIsKept) {
  // Readers deliver topic by topic: the EMCY may arrive before the node's status.
  FleetView view(kStart);
  view.Apply(EmcySample{.bus = "can0", .node_id = 6, .emcy = {.code = 0x8120}}, At(kStart + 1s), nullptr);
  view.Apply(Status(6), At(kStart + 1s), nullptr);
  const NodeRow& row = view.nodes().at({"can0", 6});
  ASSERT_TRUE(row.last_emcy.has_value());
  EXPECT_EQ(row.last_emcy->emcy.code, 0x8120);
}

// The node detail view lists a node's EMCYs: every one the Emcy topic delivered (its history is
// keep-last 32 per node), in time order whatever the arrival order, early ones included.
TEST(FleetView, EachNodeKeepsItsEmcyHistoryInTimeOrderUpToTheTopicsDepth) {
  FleetView view(kStart);
  view.Apply(EmcySample{.bus = "can0", .node_id = 6, .emcy = {.code = 0x8130}}, At(kStart + 2s), nullptr);
  view.Apply(EmcySample{.bus = "can0", .node_id = 6, .emcy = {.code = 0x8100}}, At(kStart + 1s), nullptr);
  view.Apply(Status(6), At(kStart + 3s), nullptr);
  view.Apply(EmcySample{.bus = "can0", .node_id = 6, .emcy = {.code = 0x0000}}, At(kStart + 4s), nullptr);
  view.Apply(EmcySample{.bus = "can0", .node_id = 7, .emcy = {.code = 0x8140}}, At(kStart + 4s), nullptr);
  const NodeRow& row = view.nodes().at({"can0", 6});
  ASSERT_EQ(row.emcy_history.size(), 3u);
  EXPECT_EQ(row.emcy_history[0].sample.emcy.code, 0x8100);
  EXPECT_EQ(row.emcy_history[1].sample.emcy.code, 0x8130);
  EXPECT_EQ(row.emcy_history[2].sample.emcy.code, 0x0000);
  EXPECT_EQ(row.emcy_history[2].time, kStart + 4s);

  for (int i = 0; i < 40; ++i)
    view.Apply(
        EmcySample{.bus = "can0", .node_id = 6, .emcy = {.code = static_cast<std::uint16_t>(0x1000 + i)}},
        At(kStart + 10s + std::chrono::seconds(i)), nullptr);
  const NodeRow& full = view.nodes().at({"can0", 6});
  ASSERT_EQ(full.emcy_history.size(), kEmcyHistory);
  EXPECT_EQ(full.emcy_history.back().sample.emcy.code, 0x1000 + 39);  // the oldest went first
}

TEST(FleetView, RecentEventsAreInTimeOrderWhateverTheArrivalOrder) {
  FleetView view(kStart);
  view.Apply(FaultEventSample{.bus = "can0", .fault_id = 1}, At(kStart + 2s), nullptr);
  view.Apply(EmcySample{.bus = "can0", .node_id = 1}, At(kStart + 1s), nullptr);
  ASSERT_EQ(view.recent().size(), 2u);
  EXPECT_EQ(view.recent()[0].kind, EventKind::kEmcy);
  EXPECT_EQ(view.recent()[1].kind, EventKind::kFault);
}

TEST(FleetView, FaultsAreActiveUntilCleared) {
  FleetView view(kStart);
  FaultEventSample fault{
      .bus = "can1", .fault_id = 9, .action = telemetry::FaultAction::kInjected, .kind = "drop"};
  view.Apply(fault, At(kStart + 1s), nullptr);
  EXPECT_EQ(view.buses().at("can1").active_faults.size(), 1u);
  fault.action = telemetry::FaultAction::kCleared;
  view.Apply(fault, At(kStart + 2s), nullptr);
  EXPECT_TRUE(view.buses().at("can1").active_faults.empty());
}

TEST(FleetView, SilenceForThreePeriodsIsStale) {
  FleetView view(kStart);
  view.Apply(Status(7), At(kStart), nullptr);
  const NodeRow& row = view.nodes().at({"can0", 7});
  EXPECT_FALSE(IsStale(row, kStart + 2s));
  EXPECT_TRUE(IsStale(row, kStart + 4s));
  EXPECT_TRUE(IsFaulted(row, kStart + 4s));
}

TEST(EventKind, NamesRoundTrip) {
  for (auto kind :
       {EventKind::kNodeSeen, EventKind::kNodeGone, EventKind::kNmt, EventKind::kController,
        EventKind::kErrorRegister, EventKind::kHeartbeatConsumer, EventKind::kEmcy, EventKind::kFault}) {
    EXPECT_EQ(ParseEventKind(ToString(kind)), kind);
  }
  EXPECT_EQ(ParseEventKind("nope"), std::nullopt);
}

// Issue 29: a scenario's verdicts are events of the fleet (the Verdict topic) and its status is
// the scenario line; node events carry the node's topology name.
TEST(FleetView, VerdictsAreEventsAndTheScenarioStatusIsKeptUntilItsFleetStops) {
  FleetView view(kStart);
  std::vector<FleetEvent> events;
  const VerdictSample verdict{
      .source = "demo.textproto",
      .index = 3,
      .scenario = "demo",
      .cycle = 2,
      .result = telemetry::VerdictResult::kFail,
      .name = "quad-6-emcy",
      .line = 284,
      .text = "FAIL  demo.textproto:284  quad-6-emcy: EMCY 8130h from quad-6: saw nothing"};
  view.Apply(verdict, At(kStart + 2s), &events);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, EventKind::kVerdict);
  ASSERT_TRUE(events[0].verdict);
  EXPECT_EQ(events[0].verdict->name, "quad-6-emcy");
  EXPECT_FALSE(events[0].replay);
  EXPECT_EQ(view.recent().back().kind, EventKind::kVerdict);
  // A dispose of the Verdict instance (the fleet stopped) is no verdict.
  view.Apply(verdict, {.source_time = kStart + 3s, .valid_data = false, .alive = false, .disposed = true},
             &events);
  EXPECT_EQ(events.size(), 1u);

  telemetry::ScenarioStatusSample status{.source = "demo.textproto",
                                         .scenario = "demo",
                                         .cycle = 2,
                                         .running = true,
                                         .passed = 4,
                                         .failed = 1,
                                         .pending = 3};
  view.Apply(status, At(kStart + 2s), &events);
  ASSERT_EQ(view.scenarios().size(), 1u);
  EXPECT_EQ(view.scenarios().at("demo.textproto").status.failed, 1);
  EXPECT_EQ(events.size(), 1u) << "a status is no event";
  view.Apply(status, {.source_time = kStart + 4s, .valid_data = false, .alive = false, .disposed = true},
             &events);
  EXPECT_TRUE(view.scenarios().empty());
}

TEST(FleetView, NodeEventsCarryTheNodesName) {
  FleetView view(kStart);
  std::vector<FleetEvent> events;
  NodeStatusSample s = Status(6);
  s.name = "quad-6";
  view.Apply(s, At(kStart + 1s), &events);
  view.Apply(EmcySample{.bus = "can0", .node_id = 6, .emcy = {.code = 0x8130}}, At(kStart + 2s), &events);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[1].kind, EventKind::kEmcy);
  EXPECT_EQ(events[1].name, "quad-6");
  // An EMCY taken before its node's first status is named once the status arrives.
  view.Apply(EmcySample{.bus = "can0", .node_id = 7, .emcy = {.code = 0x8130}}, At(kStart + 3s), nullptr);
  NodeStatusSample seven = Status(7);
  seven.name = "quad-7";
  view.Apply(seven, At(kStart + 3s), nullptr);
  const auto emcy = std::find_if(view.recent().begin(), view.recent().end(), [](const FleetEvent& e) {
    return e.kind == EventKind::kEmcy && e.node_id == 7;
  });
  ASSERT_NE(emcy, view.recent().end());
  EXPECT_EQ(emcy->name, "quad-7");
}

TEST(FleetView, AScenarioWithoutNewsIsStale) {
  FleetView view(kStart);
  view.Apply(telemetry::ScenarioStatusSample{.source = "a", .publish_period = 1s}, At(kStart), nullptr);
  const ScenarioRow& row = view.scenarios().at("a");
  EXPECT_FALSE(IsStale(row, kStart + 2s));
  EXPECT_TRUE(IsStale(row, kStart + 4s));
}

}  // namespace
}  // namespace canfleet::tools
