// WebState: the JSON the page gets (web/web_state.hpp), from telemetry samples with their times.
#include "web/web_state.hpp"

#include <google/protobuf/struct.pb.h>
#include <google/protobuf/util/json_util.h>
#include <gtest/gtest.h>

namespace canfleet::web {
namespace {

using namespace std::chrono_literals;
using tools::WallTime;

const WallTime kStart = WallTime(1'700'000'000s);

telemetry::SampleMeta At(WallTime t) {
  return {.source_time = t};
}

telemetry::NodeStatusSample Status(std::uint8_t id, std::string name) {
  telemetry::NodeStatusSample s;
  s.bus = "can0";
  s.node_id = id;
  s.name = std::move(name);
  s.device = "quad-controller";
  s.nmt_state = telemetry::NmtState::kOperational;
  s.heartbeat_producer_ms = 100;
  s.publish_period = 1s;
  return s;
}

/// The message parses as JSON (protobuf's parser into a Struct) and is returned as one.
google::protobuf::Struct Parse(const std::string& json) {
  google::protobuf::Struct out;
  const auto status = google::protobuf::util::JsonStringToMessage(json, &out);
  EXPECT_TRUE(status.ok()) << status.message() << "\n" << json;
  return out;
}

std::size_t Count(const google::protobuf::Struct& msg, const std::string& field) {
  return static_cast<std::size_t>(msg.fields().at(field).list_value().values_size());
}

TEST(WebState, TheFirstUpdateCarriesEverythingAndTheNextOnlyWhatIsNew) {
  WebState state(kStart);
  state.Apply(Status(5, "quad-5"), At(kStart + 1s));
  telemetry::EmcySample emcy;
  emcy.bus = "can0";
  emcy.node_id = 5;
  emcy.emcy.code = 0x8130;
  emcy.emcy.error_register = 0x01;
  state.Apply(emcy, At(kStart + 2s));

  Cursor cursor;
  const auto first = Parse(state.UpdateJson(cursor, kStart + 3s));
  EXPECT_EQ(Count(first, "nodes"), 1u);
  EXPECT_EQ(Count(first, "events"), 2u) << "node seen, EMCY";
  const auto& node = first.fields().at("nodes").list_value().values(0).struct_value().fields();
  EXPECT_EQ(node.at("key").string_value(), "can0:5");
  EXPECT_EQ(node.at("name").string_value(), "quad-5");
  EXPECT_EQ(node.at("nmt").string_value(), "operational");
  EXPECT_FALSE(node.at("faulted").bool_value());
  EXPECT_DOUBLE_EQ(node.at("last_sample").number_value(), EpochSeconds(kStart + 1s));

  const auto second = Parse(state.UpdateJson(cursor, kStart + 4s));
  EXPECT_EQ(Count(second, "events"), 0u);
  EXPECT_EQ(Count(second, "nodes"), 0u) << "a node is sent again only when it changed";
  telemetry::NodeStatusSample changed = Status(5, "quad-5");
  changed.nmt_state = telemetry::NmtState::kPreOperational;
  state.Apply(changed, At(kStart + 5s));
  const auto third = Parse(state.UpdateJson(cursor, kStart + 6s));
  ASSERT_EQ(Count(third, "nodes"), 1u);
  EXPECT_EQ(
      third.fields().at("nodes").list_value().values(0).struct_value().fields().at("nmt").string_value(),
      "pre-operational");

  // The node view asks for one node in full: its EMCY history among the rest.
  const auto detail = Parse(state.NodeJson("can0", 5, kStart + 6s));
  EXPECT_EQ(
      detail.fields().at("emcy").list_value().values(0).struct_value().fields().at("code").string_value(),
      "8130");
  EXPECT_EQ(state.NodeJson("can0", 99, kStart + 6s), "null");
}

TEST(WebState, BusStatisticsAndSignalsBecomeSeriesWithSimulatedTimeInVirtualTime) {
  WebState state(kStart);
  telemetry::BusStatsSample bus;
  bus.bus = "can0";
  bus.mode = "virtual";
  bus.load_percent = 12.5f;
  bus.frames_per_second = 400;
  bus.simulated_s = 42.5;
  state.Apply(bus, At(kStart + 1s));
  telemetry::IoSnapshotSample io;
  io.bus = "can0";
  io.node_id = 5;
  io.inputs = {{.name = "IN1.voltage_mV", .value = 1800, .unit = "mV", .text = ""}};
  state.Apply(io, At(kStart + 2s));

  Cursor cursor;
  const auto unplotted = Parse(state.UpdateJson(cursor, kStart + 3s));
  EXPECT_EQ(Count(unplotted, "points"), 3u) << "bus statistics always, a signal only when plotted";
  EXPECT_EQ(Count(unplotted, "series"), 4u) << "every series name, for the picker";
  cursor.plotted = {"io:can0:5/IN1.voltage_mV"};
  cursor.backfill = cursor.plotted;
  const auto msg = Parse(state.UpdateJson(cursor, kStart + 3s));
  ASSERT_EQ(Count(msg, "points"), 1u) << "the newly plotted series, with the points still kept";
  EXPECT_FALSE(msg.fields().contains("series")) << "no new series";
  const auto& in1 = msg.fields().at("points").list_value().values(0).list_value();
  EXPECT_EQ(in1.values(1).string_value(), "io:can0:5/IN1.voltage_mV");
  EXPECT_DOUBLE_EQ(in1.values(2).number_value(), 1800);
  EXPECT_DOUBLE_EQ(in1.values(3).number_value(), 42.5) << "the bus's latest simulated time";
  const auto& points = unplotted.fields().at("points").list_value();
  const auto& load = points.values(0).list_value();
  EXPECT_EQ(load.values(1).string_value(), "bus:can0/load");
  EXPECT_DOUBLE_EQ(load.values(2).number_value(), 12.5);
  EXPECT_DOUBLE_EQ(load.values(3).number_value(), 42.5);
}

TEST(WebState, TheRetentionWindowBoundsWhatIsKept) {
  WebState state(kStart, {.retention = 60s, .max_events = 3});
  telemetry::BusStatsSample bus;
  bus.bus = "can0";
  for (int i = 0; i < 100; ++i)
    state.Apply(bus, At(kStart + std::chrono::seconds(i)));
  for (std::uint8_t id = 1; id <= 5; ++id)
    state.Apply(Status(id, "n" + std::to_string(id)), At(kStart + 99s));
  EXPECT_EQ(state.EventCount(), 3u) << "at most max_events";
  EXPECT_EQ(state.PointCount(), 300u + 5u * 3u) << "bus statistics; each node's controller, TEC, REC";
  for (std::uint8_t id = 1; id <= 5; ++id)
    state.Apply(Status(id, "n" + std::to_string(id)), At(kStart + 99s));
  EXPECT_EQ(state.PointCount(), 315u) << "controller state and counters are kept when they change only";
  state.Trim(kStart + 100s);
  EXPECT_EQ(state.PointCount(), 3u * 60u + 15u) << "the samples of the last 60 s (40..99)";
}

TEST(WebState, NamesWithQuotesAndControlCharactersStayValidJson) {
  WebState state(kStart);
  state.Apply(Status(7, "a \"quoted\"\n\tname\\"), At(kStart + 1s));
  Cursor cursor;
  const auto msg = Parse(state.UpdateJson(cursor, kStart + 2s));
  EXPECT_EQ(msg.fields().at("nodes").list_value().values(0).struct_value().fields().at("name").string_value(),
            "a \"quoted\"\n\tname\\");
}

// A WebSocket text message must be UTF-8 (RFC 6455 §5.6): a publisher's bytes that are not become
// U+FFFD, so one odd name cannot cut every page off.
TEST(WebState, InvalidUtf8FromAPublisherBecomesReplacementCharacters) {
  EXPECT_EQ(ValidUtf8("quad-5 \xC3\xA9"), "quad-5 \xC3\xA9") << "valid UTF-8 stays";
  EXPECT_EQ(ValidUtf8("a\xFF"
                      "b"),
            "a\xEF\xBF\xBD"
            "b");
  EXPECT_EQ(ValidUtf8("\xC0\xAF"), "\xEF\xBF\xBD\xEF\xBF\xBD") << "overlong";
  EXPECT_EQ(ValidUtf8("\xED\xA0\x80"), "\xEF\xBF\xBD\xEF\xBF\xBD\xEF\xBF\xBD") << "a surrogate";
  EXPECT_EQ(ValidUtf8("\xE2\x82"), "\xEF\xBF\xBD\xEF\xBF\xBD") << "cut short";
  WebState state(kStart);
  state.Apply(Status(9, "bad \xFF name"), At(kStart + 1s));
  Cursor cursor;
  const auto msg = Parse(state.UpdateJson(cursor, kStart + 2s));
  EXPECT_EQ(msg.fields().at("nodes").list_value().values(0).struct_value().fields().at("name").string_value(),
            "bad \xEF\xBF\xBD name");
}

}  // namespace
}  // namespace canfleet::web
