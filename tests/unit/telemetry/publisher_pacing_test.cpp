// When the telemetry publishers write, on simulated time: the loop's timer runs on the test's
// SimulatedScheduler (no thread), so "nothing is due for 100 ms" and "one write per 20 ms window"
// are exact. Writes are counted by the publishers' stats(); what reaches a reader over DDS is
// tested in tests/integration/telemetry.
#include <gtest/gtest.h>

#include "clock/scheduler.hpp"
#include "telemetry/node_telemetry.hpp"
#include "telemetry/orchestrator_telemetry.hpp"

namespace canfleet::telemetry {
namespace {

using namespace std::chrono_literals;

/// A participant of its own per test (domains 90..; ctest runs each test in its own process).
DdsOptions Dds(std::uint32_t domain) {
  return {.domain_id = 90 + domain, .config_file = CANFLEET_DDS_LOOPBACK_CONFIG};
}

NodeTelemetryOptions Options(std::chrono::milliseconds period = 60s) {
  return {.bus = "pace", .node_id = 5, .device = "quad-controller", .period = period, .min_interval = 20ms};
}

TEST(PublisherPacing, TheFirstStatusGoesOutAtOnce) {
  Participant participant(Dds(1));
  SimulatedScheduler scheduler;
  NodeTelemetry telemetry(participant, Options(), scheduler);
  telemetry.UpdateStatus({});
  scheduler.Advance(0ms);
  EXPECT_EQ(telemetry.stats().state_writes, 1u);
}

TEST(PublisherPacing, AStateChangeGoesOutAtTheEndOfTheSamplingWindow) {
  Participant participant(Dds(2));
  SimulatedScheduler scheduler;
  NodeTelemetry telemetry(participant, Options(), scheduler);
  NodeStatusSnapshot status;
  telemetry.UpdateStatus(status);
  scheduler.Advance(0ms);
  ASSERT_EQ(telemetry.stats().state_writes, 1u);
  scheduler.Advance(5ms);
  status.controller_state = ControllerState::kBusOff;
  telemetry.UpdateStatus(status);
  scheduler.Advance(14ms);
  EXPECT_EQ(telemetry.stats().state_writes, 1u) << "inside the 20 ms window of the first sample";
  scheduler.Advance(1ms);
  EXPECT_EQ(telemetry.stats().state_writes, 2u) << "sampled and written when the window ends";
}

TEST(PublisherPacing, CounterOnlyUpdatesWaitForThePeriod) {
  Participant participant(Dds(3));
  SimulatedScheduler scheduler;
  NodeTelemetry telemetry(participant, Options(), scheduler);
  NodeStatusSnapshot status;
  telemetry.UpdateStatus(status);
  telemetry.Flush();
  const auto writes = telemetry.stats().state_writes;
  for (int i = 0; i < 50; ++i) {
    status.rpdo_count = static_cast<std::uint64_t>(i);
    telemetry.UpdateStatus(status);
  }
  scheduler.Advance(100ms);  // several coalescing windows: nothing is due
  EXPECT_EQ(telemetry.stats().state_writes, writes);
  telemetry.Flush();  // a flush writes the latest values anyway
  EXPECT_EQ(telemetry.stats().state_writes, writes + 1);
}

TEST(PublisherPacing, ABurstOfChangesIsCoalesced) {
  Participant participant(Dds(4));
  SimulatedScheduler scheduler;
  NodeTelemetry telemetry(participant, Options(), scheduler);
  NodeStatusSnapshot status;
  telemetry.UpdateStatus(status);
  telemetry.Flush();
  const auto before = telemetry.stats().state_writes;
  // A real change every 0.1 ms for 100 ms. (TEC cycles every 256 updates, 25.6 ms: never the same
  // value at two window ends, which would be no change.)
  for (int i = 0; i < 1000; ++i) {
    status.tec = static_cast<std::uint16_t>(i % 256);
    telemetry.UpdateStatus(status);
    scheduler.Advance(100us);
  }
  telemetry.Flush();
  // One write per 20 ms window while the burst lasted (5), plus the flush.
  EXPECT_LE(telemetry.stats().state_writes - before, 6u);
  EXPECT_GE(telemetry.stats().state_writes - before, 5u);
}

TEST(PublisherPacing, IsRepublishedEveryPeriod) {
  Participant participant(Dds(5));
  SimulatedScheduler scheduler;
  NodeTelemetry telemetry(participant, Options(50ms), scheduler);
  telemetry.UpdateStatus({});
  scheduler.Advance(0ms);
  ASSERT_EQ(telemetry.stats().state_writes, 1u);
  scheduler.Advance(49ms);
  EXPECT_EQ(telemetry.stats().state_writes, 1u);
  scheduler.Advance(1ms);
  EXPECT_EQ(telemetry.stats().state_writes, 2u);
  scheduler.Advance(200ms);
  EXPECT_EQ(telemetry.stats().state_writes, 6u) << "one every 50 ms without any update";
}

TEST(PublisherPacing, EventsGoOutAtOnceEvenInsideTheWindow) {
  Participant participant(Dds(6));
  SimulatedScheduler scheduler;
  NodeTelemetry telemetry(participant, Options(), scheduler);
  telemetry.UpdateStatus({});
  scheduler.Advance(1ms);
  telemetry.PublishEmcy({.code = 0x8130, .error_register = 0x11});
  scheduler.Advance(0ms);
  EXPECT_EQ(telemetry.stats().event_writes, 1u);
}

TEST(PublisherPacing, OrchestratorBusStatsArePacedPerBus) {
  Participant participant(Dds(7));
  SimulatedScheduler scheduler;
  OrchestratorTelemetry telemetry(participant, {.period = 1s, .min_interval = 20ms}, scheduler);
  BusStatsSnapshot stats{.bus = "ob0", .bitrate = 500000, .mode = "realtime"};
  telemetry.UpdateBusStats(stats);
  scheduler.Advance(0ms);
  EXPECT_EQ(telemetry.stats().state_writes, 1u);
  scheduler.Advance(999ms);
  EXPECT_EQ(telemetry.stats().state_writes, 1u);
  scheduler.Advance(1ms);
  EXPECT_EQ(telemetry.stats().state_writes, 2u) << "republished every period";
  telemetry.PublishFault({.bus = "ob0", .fault_id = 1, .action = FaultAction::kInjected, .kind = "drop"});
  scheduler.Advance(0ms);
  EXPECT_EQ(telemetry.stats().event_writes, 1u);
}

// Issue 29: a verdict goes out at once, after the status it changed (inside the sampling window
// too); the scenario's clock alone waits for the period.
TEST(PublisherPacing, AVerdictGoesOutAtOnceWithItsScenarioStatus) {
  Participant participant(Dds(8));
  SimulatedScheduler scheduler;
  OrchestratorTelemetry telemetry(participant, {.period = 1s, .min_interval = 20ms}, scheduler);
  ScenarioStatusSnapshot status{.source = "demo.textproto",
                                .scenario = "demo",
                                .cycle = 1,
                                .running = true,
                                .expectations = 2,
                                .pending = 2};
  telemetry.UpdateScenario(status);
  scheduler.Advance(0ms);
  ASSERT_EQ(telemetry.stats().state_writes, 1u);
  status.scenario_time_s = 0.5;  // the clock alone: no write before the period
  telemetry.UpdateScenario(status);
  scheduler.Advance(500ms);
  EXPECT_EQ(telemetry.stats().state_writes, 1u);
  status.passed = 1;
  status.pending = 1;
  telemetry.UpdateScenario(status);
  telemetry.PublishVerdict({.source = "demo.textproto", .index = 0, .scenario = "demo", .text = "pass  x"});
  scheduler.Advance(0ms);
  EXPECT_EQ(telemetry.stats().event_writes, 1u);
  EXPECT_EQ(telemetry.stats().state_writes, 2u) << "the counts that include the verdict, with it";
  telemetry.RemoveScenario("demo.textproto");
  scheduler.Advance(0ms);
  EXPECT_EQ(telemetry.stats().write_errors, 0u);
}

}  // namespace
}  // namespace canfleet::telemetry
