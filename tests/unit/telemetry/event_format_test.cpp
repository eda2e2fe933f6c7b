// `canfleet watch` lines: text for people, JSON for scripts.
#include "tools/telemetry/event_format.hpp"

#include <gtest/gtest.h>

#include "tools/telemetry/watch.hpp"

namespace canfleet::tools {
namespace {

using namespace std::chrono_literals;

const WallTime kTime = WallTime(1'700'000'000s + 123ms);  // 2023-11-14T22:13:20.123Z

FleetEvent Emcy() {
  return {.time = kTime,
          .kind = EventKind::kEmcy,
          .bus = "can0",
          .node_id = 5,
          .emcy = EmcySample{.bus = "can0",
                             .node_id = 5,
                             .emcy = {.code = 0x8130,
                                      .error_register = 0x11,
                                      .manufacturer = {1, 2, 3, 4, 0xAB},
                                      .bus_time = 5000ns}}};
}

TEST(EmcyCodes, MostSpecificClassOfCiA301Table21) {
  EXPECT_STREQ(DescribeEmcyCode(0x8130), "life guard error or heartbeat error");
  EXPECT_STREQ(DescribeEmcyCode(0x0000), "error reset or no error");
  EXPECT_STREQ(DescribeEmcyCode(0x4210), "device temperature");  // 4200h class
  EXPECT_STREQ(DescribeEmcyCode(0x5123), "device hardware");     // 5000h class
  EXPECT_STREQ(DescribeEmcyCode(0xFF42), "device specific");
}

TEST(EventText, EmcyLine) {
  EXPECT_EQ(FormatEventText(Emcy()),
            "2023-11-14T22:13:20.123Z can0 #5 EMCY 8130h reg=11h mfr=01 02 03 04 AB (life guard error or "
            "heartbeat error)");
}

TEST(EventText, StateChangeAndReplayMarker) {
  FleetEvent e{
      .time = kTime, .kind = EventKind::kNmt, .bus = "can1", .node_id = 12, .from = "PREOP", .to = "OPER"};
  e.replay = true;
  EXPECT_EQ(FormatEventText(e), "2023-11-14T22:13:20.123Z can1 #12 NMT PREOP -> OPER [history]");
}

TEST(EventText, BusWideFaultHasNoNodeNumber) {
  FleetEvent e{.time = kTime,
               .kind = EventKind::kFault,
               .bus = "can0",
               .node_id = 0,
               .fault = FaultEventSample{
                   .bus = "can0", .fault_id = 3, .kind = "partition", .parameters = {{"ms", "500"}}}};
  EXPECT_EQ(FormatEventText(e), "2023-11-14T22:13:20.123Z can0 FAULT injected #3 partition ms=500");
}

TEST(EventJson, EmcyObject) {
  EXPECT_EQ(FormatEventJson(Emcy()),
            R"({"time":"2023-11-14T22:13:20.123Z","type":"emcy","bus":"can0","node":5,"code":33072,)"
            R"("error_register":17,"manufacturer":[1,2,3,4,171],"bus_time_ns":5000,)"
            R"("text":"life guard error or heartbeat error","replay":false})");
}

TEST(EventJson, FaultObjectWithParameters) {
  FleetEvent e{.time = kTime,
               .kind = EventKind::kFault,
               .bus = "can0",
               .node_id = 7,
               .fault = FaultEventSample{.bus = "can0",
                                         .fault_id = 2,
                                         .action = telemetry::FaultAction::kCleared,
                                         .kind = "drop",
                                         .target_node = 7,
                                         .parameters = {{"cob_id", "0x707"}, {"note", "a \"quoted\"\n"}}}};
  EXPECT_EQ(FormatEventJson(e),
            R"({"time":"2023-11-14T22:13:20.123Z","type":"fault","bus":"can0","node":7,"fault_id":2,)"
            R"("action":"cleared","kind":"drop","target_node":7,"parameters":{"cob_id":"0x707",)"
            R"("note":"a \"quoted\"\n"},"bus_time_ns":0,"replay":false})");
}

TEST(EventJson, ConsumerObjectNamesThePeer) {
  FleetEvent e{.time = kTime,
               .kind = EventKind::kHeartbeatConsumer,
               .bus = "can0",
               .node_id = 2,
               .from = "active",
               .to = "timed-out",
               .peer_node = 1};
  EXPECT_EQ(FormatEventJson(e),
            R"({"time":"2023-11-14T22:13:20.123Z","type":"hb-consumer","bus":"can0","node":2,)"
            R"("peer":1,"from":"active","to":"timed-out","replay":false})");
}

TEST(EventJson, ControlCharactersAreEscaped) {
  EXPECT_EQ(JsonString(std::string("a\x01z")), R"("a\u0001z")");
}

TEST(WatchFilter, DefaultsHideFirstSightingsOnly) {
  WatchOptions options;
  FleetEvent seen{.kind = EventKind::kNodeSeen, .bus = "can0", .node_id = 1, .to = "OPER"};
  FleetEvent back{.kind = EventKind::kNodeSeen, .bus = "can0", .node_id = 1, .from = "gone", .to = "OPER"};
  EXPECT_FALSE(Selected(seen, options));
  EXPECT_TRUE(Selected(back, options));
  EXPECT_TRUE(Selected(Emcy(), options));
  options.kinds = {EventKind::kNodeSeen};
  EXPECT_TRUE(Selected(seen, options));
  EXPECT_FALSE(Selected(Emcy(), options));
}

TEST(WatchFilter, BusNodeAndHistory) {
  WatchOptions options{.bus = "can1"};
  EXPECT_FALSE(Selected(Emcy(), options));
  options = {.node = 5};
  EXPECT_TRUE(Selected(Emcy(), options));
  options = {.node = 6};
  EXPECT_FALSE(Selected(Emcy(), options));
  FleetEvent old = Emcy();
  old.replay = true;
  options = {.history = false};
  EXPECT_FALSE(Selected(old, options));
}

FleetEvent Verdict(telemetry::VerdictResult result) {
  return {.time = kTime,
          .kind = EventKind::kVerdict,
          .verdict = VerdictSample{
              .source = "topologies/demo.textproto",
              .index = 7,
              .scenario = "demo",
              .cycle = 2,
              .result = result,
              .name = "quad-6-emcy",
              .line = 284,
              .text = "FAIL  topologies/demo.textproto:284  quad-6-emcy: EMCY 8130h from quad-6 "
                      "within 4000 ms after cut-hb: saw \"nothing\"",
              .scenario_time_s = 44.5}};
}

// Issue 29: `canfleet watch` prints verdicts whole, with the line `canfleet test` prints.
TEST(EventText, VerdictLineIsTheWholeResultLine) {
  EXPECT_EQ(
      FormatEventText(Verdict(telemetry::VerdictResult::kFail)),
      "2023-11-14T22:13:20.123Z demo VERDICT cycle 2: FAIL  topologies/demo.textproto:284  quad-6-emcy: "
      "EMCY 8130h from quad-6 within 4000 ms after cut-hb: saw \"nothing\"");
  // `canfleet top`'s compact form: time of day, result, name, what was expected and seen.
  EXPECT_EQ(
      FormatEventText(Verdict(telemetry::VerdictResult::kFail), true),
      "22:13:20.123 FAIL quad-6-emcy (cycle 2): EMCY 8130h from quad-6 within 4000 ms after cut-hb: saw "
      "\"nothing\"");
}

TEST(EventJson, VerdictFields) {
  const std::string json = FormatEventJson(Verdict(telemetry::VerdictResult::kFail));
  EXPECT_NE(json.find(R"("type":"verdict")"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("source":"topologies/demo.textproto","index":7,"scenario":"demo","cycle":2,)"
                      R"("result":"FAIL","name":"quad-6-emcy","line":284,)"),
            std::string::npos)
      << json;
  EXPECT_NE(json.find(R"(saw \"nothing\"","text_cut":false,"scenario_time_s":44.500)"), std::string::npos)
      << json;
}

TEST(EventText, NodeEventsNameTheNodeAndFaultSummariesAreNeverCut) {
  FleetEvent emcy = Emcy();
  emcy.name = "quad-5";
  EXPECT_EQ(FormatEventText(emcy).rfind("2023-11-14T22:13:20.123Z can0 #5 quad-5 EMCY 8130h", 0), 0u);
  EXPECT_NE(FormatEventJson(emcy).find(R"("name":"quad-5")"), std::string::npos);
  const std::string summary(
      "drop of frames 0x185 from quad-5 on can0 (to quad-6, quad-7), probability 0.5 (seed 7), for 10s, "
      "until "
      "cleared, and then some more words to pass the 256 characters of the old bound of the buffer that "
      "printf "
      "used to fill, which cut a summary like this one in the middle of a word without saying so");
  FleetEvent fault{.time = kTime,
                   .kind = EventKind::kFault,
                   .bus = "can0",
                   .node_id = 5,
                   .fault = FaultEventSample{
                       .bus = "can0", .fault_id = 2, .kind = "drop", .parameters = {{"summary", summary}}}};
  const std::string text = FormatEventText(fault);
  EXPECT_NE(text.find("summary=" + summary), std::string::npos) << text;
}

TEST(WatchFilter, VerdictIsATypeOfItsOwn) {
  EXPECT_EQ(ParseEventKind("verdict"), EventKind::kVerdict);
  WatchOptions options;
  options.kinds = {EventKind::kVerdict};
  EXPECT_TRUE(Selected(Verdict(telemetry::VerdictResult::kPass), options));
  EXPECT_FALSE(Selected(Emcy(), options));
}

}  // namespace
}  // namespace canfleet::tools
