// The RAII wrappers over the Cyclone C API, with real DDS inside this process.
#include <gtest/gtest.h>

#include <cstdlib>

#include "telemetry/dds.hpp"
#include "telemetry/samples.hpp"
#include "telemetry/topics.hpp"
#include "test_dds.hpp"

namespace canfleet::telemetry {
namespace {

using testing::Eventually;
using testing::TestDds;

TEST(DdsError, NamesTheOperationAndTheReturnCode) {
  const DdsError error("create writer x", DDS_RETCODE_BAD_PARAMETER);
  EXPECT_EQ(error.code(), DDS_RETCODE_BAD_PARAMETER);
  EXPECT_NE(std::string(error.what()).find("create writer x: "), std::string::npos);
  EXPECT_NE(std::string(error.what()).find(dds_strretcode(-DDS_RETCODE_BAD_PARAMETER)), std::string::npos);
}

// DdsDiscovery::kMonitorsOnly (dds.hpp): the announce-only settings follow the configuration, so
// they win over it, and an explicit domain must carry CYCLONEDDS_URI, which it would ignore.
TEST(CycloneConfig, MonitorsSeeEverythingWithTheirConfigurationAsItIs) {
  EXPECT_EQ(CycloneConfig({.domain_id = 1, .config_file = "/etc/x.xml", .discovery = DdsDiscovery::kAll}),
            "file:///etc/x.xml");
  ::setenv("CYCLONEDDS_URI", "file:///from/env.xml", 1);
  EXPECT_EQ(CycloneConfig({.domain_id = 1, .config_file = "", .discovery = DdsDiscovery::kAll}),
            "file:///from/env.xml");
  ::unsetenv("CYCLONEDDS_URI");
}

// A user's second terminal: with no --dds-config and no CYCLONEDDS_URI, `canfleet top` must take
// the configuration the fleet took (issue 29: it took Cyclone's multicast default and saw nothing
// of a fleet on the loopback configuration).
TEST(CycloneConfig, WithNothingSetEveryProgramTakesTheLoopbackConfigurationOfTheRepository) {
  ::unsetenv("CYCLONEDDS_URI");
  const std::string monitor =
      CycloneConfig({.domain_id = 1, .config_file = "", .discovery = DdsDiscovery::kAll});
  EXPECT_EQ(monitor, kLoopbackConfigXml);
  EXPECT_NE(monitor.find("<NetworkInterface name=\"lo\"/>"), std::string::npos);
  EXPECT_NE(monitor.find("<Peer address=\"127.0.0.1\"/>"), std::string::npos);
  EXPECT_EQ(monitor.find("<?xml"), std::string::npos);  // one document among several: no prologue
  EXPECT_TRUE(CycloneConfig({.domain_id = 1, .config_file = "", .discovery = DdsDiscovery::kMonitorsOnly})
                  .starts_with(monitor + ",<CycloneDDS"));
  EXPECT_EQ(DescribeConfig({}), "the built-in loopback configuration (this host only)");
}

TEST(CycloneConfig, WritersAppendTheAnnounceOnlySettings) {
  const std::string config =
      CycloneConfig({.domain_id = 1, .config_file = "/etc/x.xml", .discovery = DdsDiscovery::kMonitorsOnly});
  ASSERT_TRUE(config.starts_with("file:///etc/x.xml,<CycloneDDS")) << config;
  EXPECT_NE(config.find("<AllowMulticast>false</AllowMulticast>"), std::string::npos);
  EXPECT_NE(config.find("<ParticipantIndex>none</ParticipantIndex>"), std::string::npos);
  EXPECT_NE(config.find("<SPDPInterval>1s</SPDPInterval>"), std::string::npos);
  EXPECT_NE(config.find("<Peer address=\"239.255.0.1\"/>"), std::string::npos);
}

TEST(CycloneConfig, WritersWithoutAFileKeepCycloneddsUri) {
  ::setenv("CYCLONEDDS_URI", "file:///from/env.xml", 1);
  const std::string config =
      CycloneConfig({.domain_id = 1, .config_file = "", .discovery = DdsDiscovery::kMonitorsOnly});
  ::unsetenv("CYCLONEDDS_URI");
  EXPECT_TRUE(config.starts_with("file:///from/env.xml,<CycloneDDS")) << config;
}

TEST(CycloneConfig, AWriterStartsWithTheAnnounceOnlySettings) {
  // Cyclone accepts the composed configuration (a malformed fragment would throw here).
  DdsOptions options = TestDds(27);
  options.discovery = DdsDiscovery::kMonitorsOnly;
  Participant writer(options);
  EXPECT_GT(writer.handle(), 0);
}

// The built-in configuration is one Cyclone accepts, as a monitor's and as a writer's (the two
// meeting across processes: tests/system/telemetry, "SecondTerminal").
TEST(Participant, TheBuiltInConfigurationStartsAMonitorAndAWriter) {
  ::unsetenv("CYCLONEDDS_URI");
  Participant monitor({.domain_id = 96, .config_file = "", .discovery = DdsDiscovery::kAll});
  EXPECT_GT(monitor.handle(), 0);
  Participant writer({.domain_id = 97, .config_file = "", .discovery = DdsDiscovery::kMonitorsOnly});
  EXPECT_GT(writer.handle(), 0);
}

TEST(Participant, AMissingConfigFileThrowsAtStartup) {
  EXPECT_THROW(Participant({.domain_id = 61, .config_file = "/nonexistent/cyclone.xml"}), DdsError);
}

TEST(Participant, ParticipantsShareTheDomainAndOutliveEachOther) {
  auto first = std::make_unique<Participant>(TestDds(2));
  Participant second(TestDds(2));
  first.reset();  // must not delete the domain under `second`
  Topic<canfleet_telemetry_Emcy> topic(second);
  EXPECT_GT(topic.handle(), 0);
}

TEST(Participant, ADifferentConfigForALiveDomainIsRefused) {
  Participant first(TestDds(3));
  EXPECT_THROW(Participant({.domain_id = 63, .config_file = "/etc/hostname"}), DdsError);
}

TEST(Participant, MovingTransfersOwnership) {
  Participant a(TestDds(4));
  const dds_entity_t handle = a.handle();
  Participant b(std::move(a));
  EXPECT_EQ(b.handle(), handle);
  EXPECT_EQ(a.handle(), 0);  // NOLINT(bugprone-use-after-move): the moved-from state is specified
}

TEST(Qos, EventTopicsKeepTheirDepthForLateJoiners) {
  // Cyclone serves late joiners from durability_service.history, not history: both must say 32.
  const QosPtr qos = EventQos();
  dds_history_kind_t kind;
  std::int32_t depth = 0;
  ASSERT_TRUE(dds_qget_history(qos.get(), &kind, &depth));
  EXPECT_EQ(kind, DDS_HISTORY_KEEP_LAST);
  EXPECT_EQ(depth, kEventHistoryDepth);
  dds_duration_t cleanup;
  dds_history_kind_t service_kind;
  std::int32_t service_depth = 0, a, b, c;
  ASSERT_TRUE(dds_qget_durability_service(qos.get(), &cleanup, &service_kind, &service_depth, &a, &b, &c));
  EXPECT_EQ(service_depth, kEventHistoryDepth);
  dds_durability_kind_t durability;
  ASSERT_TRUE(dds_qget_durability(qos.get(), &durability));
  EXPECT_EQ(durability, DDS_DURABILITY_TRANSIENT_LOCAL);
}

TEST(Qos, StateTopicsAreReliableKeepLastOneTransientLocal) {
  const QosPtr qos = StateQos();
  dds_reliability_kind_t reliability;
  dds_duration_t blocking;
  ASSERT_TRUE(dds_qget_reliability(qos.get(), &reliability, &blocking));
  EXPECT_EQ(reliability, DDS_RELIABILITY_RELIABLE);
  dds_history_kind_t kind;
  std::int32_t depth = 0;
  ASSERT_TRUE(dds_qget_history(qos.get(), &kind, &depth));
  EXPECT_EQ(depth, 1);
  dds_durability_kind_t durability;
  ASSERT_TRUE(dds_qget_durability(qos.get(), &durability));
  EXPECT_EQ(durability, DDS_DURABILITY_TRANSIENT_LOCAL);
}

TEST(WriterReader, ASampleWrittenIsTakenWithItsSequence) {
  Participant participant(TestDds(5));
  Topic<canfleet_telemetry_FaultEvent> topic(participant);
  Writer<canfleet_telemetry_FaultEvent> writer(participant, topic);
  Reader<canfleet_telemetry_FaultEvent> reader(participant, topic);

  canfleet_telemetry_FaultParameter parameters[2]{};
  CopyBounded(parameters[0].name, "cob_id");
  CopyBounded(parameters[0].value, "0x705");
  CopyBounded(parameters[1].name, "count");
  CopyBounded(parameters[1].value, "3");
  canfleet_telemetry_FaultEvent sample{};
  CopyBounded(sample.bus, "wr");
  sample.fault_id = 4;
  CopyBounded(sample.kind, "drop");
  sample.parameters = {2, 2, parameters, false};
  ASSERT_EQ(writer.Write(sample), DDS_RETCODE_OK);

  std::vector<FaultEventSample> got;
  ASSERT_TRUE(Eventually([&] {
    reader.Take([&](const auto& s, const dds_sample_info_t& info) {
      if (info.valid_data) got.push_back(FromDds(s));
    });
    return !got.empty();
  }));
  EXPECT_EQ(got[0].kind, "drop");
  ASSERT_EQ(got[0].parameters.size(), 2u);
  EXPECT_EQ(got[0].parameters[0], std::make_pair(std::string("cob_id"), std::string("0x705")));
}

TEST(WriterReader, TheReaderReusesItsSampleBuffers) {
  // Steady-state reading must not allocate per sample: the sequence buffer deserialised into by
  // the first take is reused by the next one of the same size.
  Participant participant(TestDds(6));
  Topic<canfleet_telemetry_FaultEvent> topic(participant);
  Writer<canfleet_telemetry_FaultEvent> writer(participant, topic);
  Reader<canfleet_telemetry_FaultEvent> reader(participant, topic, nullptr, 1);
  canfleet_telemetry_FaultParameter parameters[1]{};
  canfleet_telemetry_FaultEvent sample{};
  CopyBounded(sample.bus, "reuse");
  sample.parameters = {1, 1, parameters, false};

  std::vector<const void*> buffers;
  for (int i = 0; i < 2; ++i) {
    sample.fault_id = static_cast<std::uint32_t>(i);
    ASSERT_EQ(writer.Write(sample), DDS_RETCODE_OK);
    ASSERT_TRUE(Eventually([&] {
      return reader.Take([&](const auto& s, const auto&) { buffers.push_back(s.parameters._buffer); }) > 0;
    }));
  }
  ASSERT_EQ(buffers.size(), 2u);
  EXPECT_EQ(buffers[0], buffers[1]);
}

TEST(WriterReader, ALateReaderGetsTheHistoryOfEveryInstance) {
  Participant participant(TestDds(7));
  Topic<canfleet_telemetry_Emcy> topic(participant);
  Writer<canfleet_telemetry_Emcy> writer(participant, topic);
  canfleet_telemetry_Emcy emcy{};
  CopyBounded(emcy.bus, "late");
  for (std::uint8_t node = 1; node <= 3; ++node) {
    emcy.node_id = node;
    for (std::uint16_t i = 0; i < 40; ++i) {  // more than the depth: the oldest fall out
      emcy.code = i;
      ASSERT_EQ(writer.Write(emcy), DDS_RETCODE_OK);
    }
  }
  Reader<canfleet_telemetry_Emcy> reader(participant, topic);  // joins after the writes
  std::map<int, int> per_node;
  ASSERT_TRUE(Eventually([&] {
    reader.TakeAll([&](const auto& s, const auto& info) {
      if (info.valid_data) ++per_node[s.node_id];
    });
    return per_node.size() == 3 && per_node[1] == kEventHistoryDepth && per_node[3] == kEventHistoryDepth;
  }));
  EXPECT_EQ(per_node[2], kEventHistoryDepth);
}

TEST(WaitSet, TriggerWakesAWait) {
  Participant participant(TestDds(8));
  WaitSet waitset(participant);
  waitset.Trigger();
  EXPECT_TRUE(waitset.Wait(std::chrono::seconds(5)));
  waitset.ClearTrigger();
  EXPECT_FALSE(waitset.Wait(std::chrono::milliseconds(10)));
}

}  // namespace
}  // namespace canfleet::telemetry
