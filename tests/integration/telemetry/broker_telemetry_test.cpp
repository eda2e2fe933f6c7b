// orchestrator/broker_telemetry: BusStats sampled from a Broker on simulated time, FaultEvents
// paired by fault_id, read back over real DDS by a FleetReader.
#include "orchestrator/broker_telemetry/broker_telemetry.hpp"

#include <gtest/gtest.h>

#include "telemetry/fleet_reader.hpp"
#include "test_dds.hpp"

namespace canfleet::broker {
namespace {

using namespace std::chrono_literals;
using telemetry::testing::Eventually;
using telemetry::testing::TestDds;

class NullSink final : public PortSink {
 public:
  void Deliver(std::span<const TimedFrame>) override {}
  void ControllerChanged(const ControllerEvent&) override {}
};

CanFrame Frame(std::uint32_t id) {
  CanFrame f;
  f.id = id;
  f.dlc = 8;
  return f;
}

TEST(BrokerTelemetrySnapshot, CarriesTheBrokersStatisticsAndFlagsExtendedIds) {
  BusStats stats;
  stats.name = "can0";
  stats.bitrate = 250000;
  stats.paced = true;
  stats.ports = 3;
  stats.load_percent = 12.5;
  stats.frames_per_s = 100;
  stats.frames = 1234;
  stats.error_frames = 7;
  stats.top_ids = {{.id = 0x181, .extended = false, .frames = 50, .frames_per_s = 50},
                   {.id = 0x1ABCDEF, .extended = true, .frames = 10, .frames_per_s = 10}};
  const telemetry::BusStatsSnapshot s = ToSnapshot(stats);
  EXPECT_EQ(s.bus, "can0");
  EXPECT_EQ(s.bitrate, 250000u);
  EXPECT_EQ(s.mode, "realtime");
  EXPECT_FLOAT_EQ(s.load_percent, 12.5f);
  EXPECT_FLOAT_EQ(s.frames_per_second, 100.0f);
  EXPECT_EQ(s.frames_total, 1234u);
  EXPECT_EQ(s.error_frames, 7u);
  EXPECT_EQ(s.node_count, 3);
  ASSERT_EQ(s.top_cob_id_count, 2);
  EXPECT_EQ(s.top_cob_ids[0], (telemetry::CobIdRate{0x181, 50.0f}));
  EXPECT_EQ(s.top_cob_ids[1], (telemetry::CobIdRate{0x8000'0000u | 0x1ABCDEF, 10.0f}));

  stats.paced = false;
  stats.top_ids.assign(40, {.id = 0x100, .frames_per_s = 1});
  const telemetry::BusStatsSnapshot unpaced = ToSnapshot(stats);
  EXPECT_EQ(unpaced.mode, "unpaced");
  EXPECT_EQ(unpaced.top_cob_id_count, telemetry::kMaxTopCobIds);  // the IDL's bound
}

class BrokerTelemetryTest : public ::testing::Test {
 protected:
  BrokerTelemetryTest()
      : participant_(TestDds(26)),
        reader_(participant_,
                {.node_status = {},
                 .emcy = {},
                 .io = {},
                 .bus_stats = [this](const auto& s, const auto& m) { stats_.emplace_back(s, m); },
                 .fault = [this](const auto& s, const auto& m) { faults_.emplace_back(s, m); }}),
        publisher_(participant_) {
    broker_.AddBus({.name = "bt0", .bitrate = 500'000});
    a_ = broker_.Attach("bt0", "a", sink_a_);
    b_ = broker_.Attach("bt0", "b", sink_b_);
  }
  bool Until(const std::function<bool()>& condition) {
    return Eventually([&] {
      reader_.Poll();
      return condition();
    });
  }
  const telemetry::BusStatsSample* LastStats() const {
    for (auto it = stats_.rbegin(); it != stats_.rend(); ++it)
      if (it->second.valid_data && it->second.alive) return &it->first;
    return nullptr;
  }

  SimulatedScheduler scheduler_;
  Broker broker_{scheduler_};
  NullSink sink_a_, sink_b_;
  PortId a_ = 0, b_ = 0;
  telemetry::Participant participant_;
  std::vector<std::pair<telemetry::BusStatsSample, telemetry::SampleMeta>> stats_;
  std::vector<std::pair<telemetry::FaultEventSample, telemetry::SampleMeta>> faults_;
  telemetry::FleetReader reader_;
  telemetry::OrchestratorTelemetry publisher_;
};

// The bus appears at once (ports, bitrate); the traffic of the next period is counted at the next
// sample, with its busiest identifier.
TEST_F(BrokerTelemetryTest, SamplesEveryBusEveryPeriod) {
  BrokerTelemetry telemetry(broker_, scheduler_, publisher_, {.period = 1000ms});
  ASSERT_TRUE(Until([&] { return LastStats() && LastStats()->node_count == 2; }));
  EXPECT_EQ(LastStats()->bus, "bt0");
  EXPECT_EQ(LastStats()->bitrate, 500000u);
  EXPECT_EQ(LastStats()->mode, "realtime");
  EXPECT_EQ(LastStats()->frames_total, 0u);

  for (int i = 0; i < 10; ++i)
    broker_.Submit(a_, Frame(0x181));
  broker_.Submit(b_, Frame(0x701));
  scheduler_.Advance(1000ms);
  ASSERT_TRUE(Until([&] { return LastStats()->frames_total == 11; }));
  ASSERT_FALSE(LastStats()->top_cob_ids.empty());
  EXPECT_EQ(LastStats()->top_cob_ids[0].cob_id, 0x181u);
  EXPECT_GT(LastStats()->load_percent, 0.0f);

  // A port leaves: the node count follows.
  broker_.Detach(b_);
  scheduler_.Advance(1000ms);
  ASSERT_TRUE(Until([&] { return LastStats()->node_count == 1; }));
}

// Destroying the sampler disposes the buses it published: monitors drop them.
TEST_F(BrokerTelemetryTest, DestroyingItDisposesTheBusStats) {
  auto telemetry = std::make_unique<BrokerTelemetry>(broker_, scheduler_, publisher_);
  ASSERT_TRUE(Until([&] { return LastStats() != nullptr; }));
  telemetry.reset();
  ASSERT_TRUE(Until([&] { return !stats_.back().second.alive; }));
  EXPECT_EQ(stats_.back().first.bus, "bt0");
}

// Injected and cleared share the fault_id; the clearing repeats kind, target and parameters.
TEST_F(BrokerTelemetryTest, FaultsArePairedByTheirId) {
  BrokerTelemetry telemetry(broker_, scheduler_, publisher_);
  const RuleId rule = broker_.Faults("bt0").Add({.id = 0x705, .mask = 0x7FF, .action = RuleAction::kDrop});
  EXPECT_EQ(telemetry.PublishFaultInjected({.bus = "bt0",
                                            .fault_id = rule,
                                            .kind = "drop",
                                            .target_node = 5,
                                            .parameters = {{"cob_id", "0x705"}}}),
            rule);
  const std::uint32_t assigned =
      telemetry.PublishFaultInjected({.bus = "bt0", .kind = "bus-off", .target_node = 6});
  EXPECT_NE(assigned, 0u);
  EXPECT_NE(assigned, rule);
  EXPECT_EQ(telemetry.ActiveFaults().size(), 2u);
  scheduler_.Advance(250ms);
  EXPECT_TRUE(telemetry.PublishFaultCleared("bt0", rule));
  EXPECT_FALSE(telemetry.PublishFaultCleared("bt0", rule));  // not active any more
  EXPECT_FALSE(telemetry.PublishFaultCleared("other", assigned));
  EXPECT_EQ(telemetry.ActiveFaults().size(), 1u);

  ASSERT_TRUE(Until([&] { return faults_.size() == 3; }));
  const auto& injected = faults_[0].first;
  const auto& cleared = faults_[2].first;
  EXPECT_EQ(injected.fault_id, rule);
  EXPECT_EQ(injected.action, telemetry::FaultAction::kInjected);
  EXPECT_EQ(injected.kind, "drop");
  EXPECT_EQ(injected.target_node, 5);
  EXPECT_EQ(injected.parameters, (std::vector<std::pair<std::string, std::string>>{{"cob_id", "0x705"}}));
  EXPECT_EQ(cleared.fault_id, rule);
  EXPECT_EQ(cleared.action, telemetry::FaultAction::kCleared);
  EXPECT_EQ(cleared.kind, "drop");
  EXPECT_EQ(cleared.parameters, injected.parameters);
  // Bus time: the broker's scheduler time line.
  EXPECT_EQ(cleared.bus_time - injected.bus_time, std::chrono::milliseconds(250));
}

}  // namespace
}  // namespace canfleet::broker
