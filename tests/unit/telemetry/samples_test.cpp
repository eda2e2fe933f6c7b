// Conversions between the idlc-generated C samples and the C++ values tools work on.
#include <gtest/gtest.h>

#include <cstring>

#include "telemetry/node_telemetry.hpp"
#include "telemetry/orchestrator_telemetry.hpp"
#include "telemetry/samples.hpp"

namespace canfleet::telemetry {
namespace {

TEST(Bounded, CopyTruncatesAndTerminates) {
  char text[8];
  CopyBounded(text, "can0");
  EXPECT_STREQ(text, "can0");
  CopyBounded(text, "a-very-long-bus-name");
  EXPECT_STREQ(text, "a-very-");  // IDL string<7>: 7 characters and the terminator
}

TEST(Bounded, FromBoundedStopsAtTheArrayEndWithoutTerminator) {
  char text[4] = {'a', 'b', 'c', 'd'};
  EXPECT_EQ(FromBounded(text), "abcd");
}

TEST(Enums, NmtStatesRoundTripAndUnknownIsNullopt) {
  for (auto state :
       {NmtState::kInitialising, NmtState::kStopped, NmtState::kOperational, NmtState::kPreOperational}) {
    EXPECT_EQ(FromDds(ToDds(std::optional<NmtState>(state))), state);
  }
  EXPECT_EQ(ToDds(std::optional<NmtState>()), canfleet_telemetry_NMT_UNKNOWN);
  EXPECT_EQ(FromDds(canfleet_telemetry_NMT_UNKNOWN), std::nullopt);
}

TEST(Enums, ControllerAndConsumerStatesRoundTrip) {
  for (auto state :
       {ControllerState::kErrorActive, ControllerState::kErrorPassive, ControllerState::kBusOff}) {
    EXPECT_EQ(FromDds(ToDds(state)), state);
  }
  for (auto state : {HeartbeatConsumerState::kUnknown, HeartbeatConsumerState::kActive,
                     HeartbeatConsumerState::kTimedOut}) {
    EXPECT_EQ(FromDds(ToDds(state)), state);
  }
  EXPECT_EQ(FromDds(ToDds(FaultAction::kCleared)), FaultAction::kCleared);
}

TEST(FromDds, NodeStatusCopiesEveryField) {
  canfleet_telemetry_HeartbeatConsumer consumers[2] = {
      {3, 250, canfleet_telemetry_HB_CONSUMER_ACTIVE, canfleet_telemetry_NMT_OPERATIONAL},
      {4, 300, canfleet_telemetry_HB_CONSUMER_TIMED_OUT, canfleet_telemetry_NMT_UNKNOWN}};
  canfleet_telemetry_NodeStatus s{};
  CopyBounded(s.bus, "can1");
  s.node_id = 9;
  CopyBounded(s.device, "quad-controller");
  s.nmt_state = canfleet_telemetry_NMT_PRE_OPERATIONAL;
  s.error_register = 0x11;
  s.controller_state = canfleet_telemetry_CONTROLLER_ERROR_PASSIVE;
  s.tec = 130;
  s.rec = 7;
  s.heartbeat_producer_ms = 100;
  s.heartbeat_consumers = {2, 2, consumers, false};
  s.rpdo_count = 5;
  s.tpdo_count = 6;
  s.uptime_ms = 61000;
  s.last_emcy = {true, 0x8130, 0x11, 1234};
  s.publish_period_ms = 1000;
  s.serial = 77;

  const NodeStatusSample out = FromDds(s);
  EXPECT_EQ(out.bus, "can1");
  EXPECT_EQ(out.node_id, 9);
  EXPECT_EQ(out.device, "quad-controller");
  EXPECT_EQ(out.nmt_state, NmtState::kPreOperational);
  EXPECT_EQ(out.error_register, 0x11);
  EXPECT_EQ(out.controller_state, ControllerState::kErrorPassive);
  EXPECT_EQ(out.tec, 130);
  EXPECT_EQ(out.rec, 7);
  ASSERT_EQ(out.heartbeat_consumers.size(), 2u);
  EXPECT_EQ(out.heartbeat_consumers[1].node_id, 4);
  EXPECT_EQ(out.heartbeat_consumers[1].state, HeartbeatConsumerState::kTimedOut);
  EXPECT_EQ(out.heartbeat_consumers[1].last_state, std::nullopt);
  EXPECT_EQ(out.uptime, std::chrono::milliseconds(61000));
  ASSERT_TRUE(out.last_emcy.has_value());
  EXPECT_EQ(out.last_emcy->code, 0x8130);
  EXPECT_EQ(out.last_emcy->bus_time, BusTime(1234));
  EXPECT_EQ(out.publish_period, std::chrono::milliseconds(1000));
  EXPECT_EQ(out.serial, 77u);
}

TEST(FromDds, SequenceLengthIsClampedToItsBound) {
  // A locally built sample claiming more entries than the IDL allows is read up to the bound.
  std::vector<canfleet_telemetry_CobIdRate> rates(40);
  canfleet_telemetry_BusStats s{};
  s.top_cob_ids = {40, 40, rates.data(), false};
  EXPECT_EQ(FromDds(s).top_cob_ids.size(), kMaxTopCobIds);
}

TEST(FromDds, NoValidLastEmcyMeansNullopt) {
  canfleet_telemetry_NodeStatus s{};
  EXPECT_FALSE(FromDds(s).last_emcy.has_value());
}

TEST(StatusChanged, CountersAloneAreNotAChange) {
  NodeStatusSnapshot a;
  NodeStatusSnapshot b = a;
  b.rpdo_count = 100;
  b.tpdo_count = 100;
  EXPECT_FALSE(StatusChanged(a, b));
  b.tec = 1;
  EXPECT_TRUE(StatusChanged(a, b));
}

TEST(StatusChanged, OnlyTheUsedConsumerEntriesCount) {
  NodeStatusSnapshot a;
  a.heartbeat_consumer_count = 1;
  NodeStatusSnapshot b = a;
  b.heartbeat_consumers[5].state = HeartbeatConsumerState::kTimedOut;  // beyond the count: ignored
  EXPECT_FALSE(StatusChanged(a, b));
  b.heartbeat_consumers[0].state = HeartbeatConsumerState::kTimedOut;
  EXPECT_TRUE(StatusChanged(a, b));
}

// Issue 29: bounded text is never cut mid-word silently.
TEST(Bounded, CutAtWordKeepsWordsWholeAndMarksTheCut) {
  char text[16];  // IDL string<15>
  EXPECT_FALSE(CopyBoundedAtWord(text, "short one"));
  EXPECT_STREQ(text, "short one");
  EXPECT_TRUE(CopyBoundedAtWord(text, "to all receivers of can0"));
  EXPECT_STREQ(text, "to all...");  // "to all receiv" would cut a word
  EXPECT_TRUE(CopyBoundedAtWord(text, "averyveryverylongword"));
  EXPECT_STREQ(text, "averyveryver...");  // one word longer than the room: cut, and marked
  EXPECT_EQ(CutAtWord("exactly fifteen", 15), 15u);
  EXPECT_EQ(CutAtWord("", 3), 0u);
}

TEST(Bounded, FaultValuesHold255Characters) {
  canfleet_telemetry_FaultParameter p{};
  const std::string summary(200, 'x');
  CopyBoundedAtWord(p.value, summary);
  EXPECT_EQ(FromBounded(p.value), summary);
}

TEST(StateNames, AreTheWordsOfTheCliAndTheExpectations) {
  EXPECT_STREQ(StateName(std::optional<NmtState>(NmtState::kPreOperational)), "pre-operational");
  EXPECT_STREQ(StateName(std::optional<NmtState>(NmtState::kOperational)), "operational");
  EXPECT_STREQ(StateName(std::optional<NmtState>(NmtState::kStopped)), "stopped");
  EXPECT_STREQ(StateName(std::optional<NmtState>(NmtState::kInitialising)), "initialising");
  EXPECT_STREQ(StateName(std::optional<NmtState>()), "unknown");
  EXPECT_STREQ(StateName(ControllerState::kErrorActive), "error-active");
  EXPECT_STREQ(StateName(ControllerState::kErrorPassive), "error-passive");
  EXPECT_STREQ(StateName(ControllerState::kBusOff), "bus-off");
}

TEST(FromDds, VerdictAndScenarioStatusCopyEveryFieldAndSurviveHostileSamples) {
  canfleet_telemetry_Verdict v{};
  CopyBounded(v.source, "topologies/demo.textproto");
  v.index = 7;
  CopyBounded(v.scenario, "demo");
  v.cycle = 3;
  v.result = canfleet_telemetry_VERDICT_FAIL;
  CopyBounded(v.name, "quad-6-emcy");
  v.line = 284;
  CopyBounded(v.text, "FAIL  topologies/demo.textproto:284  quad-6-emcy: ...");
  v.text_cut = true;
  v.scenario_time_s = 42.5;
  v.serial = 9;
  const VerdictSample s = FromDds(v);
  EXPECT_EQ(s.source, "topologies/demo.textproto");
  EXPECT_EQ(s.index, 7);
  EXPECT_EQ(s.scenario, "demo");
  EXPECT_EQ(s.cycle, 3u);
  EXPECT_EQ(s.result, VerdictResult::kFail);
  EXPECT_EQ(s.name, "quad-6-emcy");
  EXPECT_EQ(s.line, 284u);
  EXPECT_TRUE(s.text_cut);
  EXPECT_EQ(s.scenario_time_s, 42.5);
  EXPECT_EQ(s.serial, 9u);

  // Unterminated strings and an enum value no writer of ours sends.
  std::memset(v.text, 'A', sizeof v.text);
  std::memset(v.source, 'B', sizeof v.source);
  const int bad = 77;  // as a hostile writer's bytes would decode
  static_assert(sizeof bad == sizeof v.result);
  std::memcpy(&v.result, &bad, sizeof v.result);
  const VerdictSample hostile = FromDds(v);
  EXPECT_EQ(hostile.text.size(), sizeof v.text);
  EXPECT_EQ(hostile.source.size(), sizeof v.source);
  EXPECT_EQ(hostile.result, VerdictResult::kError);

  canfleet_telemetry_ScenarioStatus st{};
  CopyBounded(st.source, "demo.textproto");
  CopyBounded(st.scenario, "demo");
  CopyBounded(st.time_mode, "virtual");
  st.scenario_time_s = 12.5;
  st.cycle = 2;
  st.running = true;
  st.expectations = 27;
  st.passed = 20;
  st.failed = 1;
  st.skipped = 2;
  st.pending = 4;
  CopyBounded(st.step, "cut-hb");
  st.step_time_s = 10;
  st.publish_period_ms = 1000;
  std::memset(st.time_mode, 'v', sizeof st.time_mode);  // unterminated
  const ScenarioStatusSample ss = FromDds(st);
  EXPECT_EQ(ss.scenario, "demo");
  EXPECT_EQ(ss.time_mode, std::string(sizeof st.time_mode, 'v'));
  EXPECT_EQ(ss.cycle, 2u);
  EXPECT_TRUE(ss.running);
  EXPECT_EQ(ss.expectations, 27);
  EXPECT_EQ(ss.passed, 20);
  EXPECT_EQ(ss.failed, 1);
  EXPECT_EQ(ss.skipped, 2);
  EXPECT_EQ(ss.pending, 4);
  EXPECT_EQ(ss.step, "cut-hb");
  EXPECT_EQ(ss.publish_period, std::chrono::milliseconds(1000));
}

TEST(FromDds, NodeNameAndIoWords) {
  canfleet_telemetry_NodeStatus s{};
  CopyBounded(s.name, "psu-34");
  EXPECT_EQ(FromDds(s).name, "psu-34");
  canfleet_telemetry_IoValue values[1]{};
  CopyBounded(values[0].name, "PS.state");
  values[0].value = 1;
  CopyBounded(values[0].text, "on");
  canfleet_telemetry_IoSnapshot io{};
  io.outputs = {1, 1, values, false};
  const IoSnapshotSample sample = FromDds(io);
  ASSERT_EQ(sample.outputs.size(), 1u);
  EXPECT_EQ(sample.outputs[0].text, "on");
}

TEST(SourceKey, ALongFileKeepsItsEnd) {
  EXPECT_EQ(SourceKey("demo.textproto"), "demo.textproto");
  const std::string path = "/tmp/" + std::string(200, 'd') + "/my-scenario.textproto";
  const std::string key = SourceKey(path);
  EXPECT_EQ(key.size(), kMaxScenarioSource);
  EXPECT_EQ(key.rfind("...", 0), 0u);
  EXPECT_EQ(key.substr(key.size() - 22), "/my-scenario.textproto");
}

}  // namespace
}  // namespace canfleet::telemetry
