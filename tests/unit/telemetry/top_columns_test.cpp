// `canfleet top` at 80 columns (issue 29, point 3): a NODE column with the topology's names, the
// state words of the CLI and the expectations, columns chosen by priority to fit the width, a
// selection marked at the start of its row, and every line (title, buses, scenario, events) within
// the width, cut at a word boundary with a marker when it must be cut.
#include <gtest/gtest.h>

#include <sstream>

#include "tests/support/text_lines.hpp"
#include "tools/telemetry/node_detail.hpp"
#include "tools/telemetry/text_fit.hpp"
#include "tools/telemetry/top_format.hpp"

namespace canfleet::tools {
namespace {

using namespace std::chrono_literals;
using telemetry::ControllerState;
using telemetry::NmtState;

const WallTime kNow = WallTime(1'700'000'000s);

SampleMeta At(WallTime t) {
  return {.source_time = t};
}

using ::canfleet::test::Lines;

/// The header line of the node table.
std::string Header(const std::vector<std::string>& lines) {
  for (const auto& line : lines)
    if (line.find("NODE") != std::string::npos && line.find("NMT") != std::string::npos) return line;
  return "";
}

std::string Row(const std::vector<std::string>& lines, const std::string& name) {
  for (const auto& line : lines)
    if (line.find(" " + name + " ") != std::string::npos) return line;
  return "";
}

/// The demo's fleet as the issue saw it: ten nodes, two buses, the supply bus-off, quad-6
/// pre-operational after a lost heartbeat, a scenario running with a failed expectation.
class DemoFleet : public ::testing::Test {
 protected:
  void SetUp() override {
    Add("can0", 5, "quad-5", "quad-controller");
    Add("can0", 6, "quad-6", "quad-controller", [](NodeStatusSample& s) {
      s.nmt_state = NmtState::kPreOperational;
      s.error_register = 0x01;
      s.heartbeat_consumers = {{.node_id = 5,
                                .time_ms = 1500,
                                .state = telemetry::HeartbeatConsumerState::kTimedOut,
                                .last_state = NmtState::kOperational}};
      s.last_emcy = telemetry::EmcyInfo{.code = 0x8130, .error_register = 0x01};
    });
    Add("can0", 7, "quad-7", "quad-controller");
    Add("can0", 20, "dio-20", "generic");
    Add("can0", 32, "valve-32", "valve-12in12out");
    Add("can0", 33, "encoder-33", "encoder-dual-valve");
    Add("can0", 34, "psu-34", "power-supply-24v-350w", [](NodeStatusSample& s) {
      s.controller_state = ControllerState::kBusOff;
      s.tec = 256;
    });
    Add("can1", 9, "quad-9", "quad-controller");
    Add("can0", 10, "datalogger", "datalogger-tc-analog", [](NodeStatusSample& s) {
      s.controller_state = ControllerState::kErrorPassive;
      s.tec = 128;
    });
    Add("can1", 11, "datalogger", "datalogger-tc-analog");
    telemetry::BusStatsSample can0{.bus = "can0",
                                   .bitrate = 250000,
                                   .mode = "realtime",
                                   .load_percent = 4.8F,
                                   .frames_per_second = 128,
                                   .node_count = 9};
    can0.top_cob_ids = {{0x185, 10}, {0x186, 10}, {0x187, 10}, {0x285, 10}};
    view_.Apply(can0, At(kNow - 1s), nullptr);
    view_.Apply(FaultEventSample{.bus = "can0",
                                 .fault_id = 3,
                                 .kind = "bus-off",
                                 .target_node = 34,
                                 .parameters = {{"summary", "bus-off of psu-34 on can0, until cleared"}}},
                At(kNow - 3s), nullptr);
    view_.Apply(telemetry::ScenarioStatusSample{.source = "topologies/demo.textproto",
                                                .scenario = "demo",
                                                .time_mode = "real",
                                                .scenario_time_s = 82.3,
                                                .cycle = 2,
                                                .running = true,
                                                .expectations = 27,
                                                .passed = 21,
                                                .failed = 1,
                                                .pending = 5,
                                                .step = "off-psu",
                                                .step_time_s = 80,
                                                .publish_period = 1s},
                At(kNow - 500ms), nullptr);
    view_.Apply(
        VerdictSample{.source = "topologies/demo.textproto",
                      .index = 7,
                      .scenario = "demo",
                      .cycle = 2,
                      .result = telemetry::VerdictResult::kFail,
                      .name = "quad-6-emcy",
                      .line = 284,
                      .text = "FAIL  topologies/demo.textproto:284  quad-6-emcy: EMCY 8130h from quad-6 "
                              "within 4000 ms after cut-hb: saw nothing within the window"},
        At(kNow - 2s), nullptr);
    view_.Apply(
        VerdictSample{.source = "topologies/demo.textproto",
                      .index = 6,
                      .scenario = "demo",
                      .cycle = 2,
                      .result = telemetry::VerdictResult::kPass,
                      .name = "pout-on",
                      .line = 276,
                      .text = "pass  topologies/demo.textproto:276  pout-on: quad-6 OUT1.current_mA in "
                              "1100..1300 within 3000 ms after the start: 1200 mA at t=35.100 s"},
        At(kNow - 4s), nullptr);
  }

  void Add(const std::string& bus, std::uint8_t id, const std::string& name, const std::string& device,
           void (*change)(NodeStatusSample&) = nullptr) {
    NodeStatusSample s{.bus = bus, .node_id = id, .device = device, .name = name};
    s.nmt_state = NmtState::kOperational;
    s.publish_period = 1s;
    s.uptime = 38s;
    s.heartbeat_producer_ms = 500;
    view_.Apply(s, At(kNow - 60s), nullptr);
    if (change) change(s);
    view_.Apply(s, At(kNow - 200ms), nullptr);
  }

  FleetView view_{kNow - 120s};
};

TEST_F(DemoFleet, EveryLineFits80ColumnsAndRowsNameTheNodeWithTheCliWords) {
  const RenderSettings settings{.width = 80, .height = 40, .color = false, .now = kNow};
  const auto lines = Lines(RenderFrame(view_, settings));
  for (const auto& line : lines)
    EXPECT_LE(line.size(), 80u) << line;
  const std::string header = Header(lines);
  ASSERT_FALSE(header.empty());
  // The ten columns of the 80-column set, in their order; the wider set is left out.
  std::size_t at = 0;
  for (const char* column :
       {"NODE", "BUS", "ID", "NMT", "CONTROLLER", "TEC", "REC", "ERR", "CONS", "LAST EMCY"}) {
    const auto found = header.find(column, at);
    EXPECT_NE(found, std::string::npos) << column << " in " << header;
    at = found == std::string::npos ? at : found;
  }
  for (const char* column : {"DEVICE", "HB ms", "RPDO", "TPDO", "UPTIME"})
    EXPECT_EQ(header.find(column), std::string::npos) << column << " in " << header;

  const std::string quad6 = Row(lines, "quad-6");
  EXPECT_EQ(quad6.rfind("  quad-6", 0), 0u) << quad6;  // the name leads the row
  EXPECT_NE(quad6.find("pre-operational"), std::string::npos) << quad6;
  EXPECT_NE(quad6.find("error-active"), std::string::npos) << quad6;
  EXPECT_NE(quad6.find("0/1 !1"), std::string::npos) << quad6;
  EXPECT_NE(quad6.find("8130h"), std::string::npos) << quad6;
  EXPECT_NE(Row(lines, "psu-34").find("bus-off"), std::string::npos);
  EXPECT_NE(Row(lines, "psu-34").find("256"), std::string::npos);
  EXPECT_NE(Row(lines, "datalogger").find("error-passive"), std::string::npos);
  EXPECT_EQ(RenderFrame(view_, settings).find("PREOP"), std::string::npos);
}

TEST_F(DemoFleet, WiderScreensAddDeviceHeartbeatPdoCountersAndUptime) {
  const RenderSettings settings{.width = 160, .height = 40, .color = false, .now = kNow};
  const auto lines = Lines(RenderFrame(view_, settings));
  const std::string header = Header(lines);
  for (const char* column : {"NODE", "DEVICE", "NMT", "HB ms", "RPDO", "TPDO", "UPTIME", "LAST EMCY", "AGE"})
    EXPECT_NE(header.find(column), std::string::npos) << column << " in " << header;
  EXPECT_NE(Row(lines, "psu-34").find("power-supply-24v-350w"), std::string::npos);
  EXPECT_NE(Row(lines, "quad-5").find("0:00:38"), std::string::npos);
}

TEST_F(DemoFleet, AHealthyFleetShowsTheAgeAt80Columns) {
  FleetView healthy{kNow - 120s};
  for (const std::uint8_t id : {std::uint8_t{5}, std::uint8_t{6}, std::uint8_t{7}}) {
    healthy.Apply(NodeStatusSample{.bus = "can0",
                                   .node_id = id,
                                   .device = "quad-controller",
                                   .name = "quad-" + std::to_string(id),
                                   .nmt_state = NmtState::kOperational,
                                   .publish_period = 1s},
                  At(kNow - 300ms), nullptr);
  }
  const RenderSettings settings{.width = 80, .height = 40, .color = false, .now = kNow};
  const std::string header = Header(Lines(RenderFrame(healthy, settings)));
  EXPECT_NE(header.find("AGE"), std::string::npos) << header;
  EXPECT_LE(header.size(), 80u);
}

TEST_F(DemoFleet, ANarrowScreenKeepsTheMostImportantColumns) {
  const RenderSettings settings{.width = 50, .height = 40, .color = false, .now = kNow};
  const auto lines = Lines(RenderFrame(view_, settings));
  for (const auto& line : lines)
    EXPECT_LE(line.size(), 50u) << line;
  const std::string header = Header(lines);
  EXPECT_NE(header.find("NODE"), std::string::npos) << header;
  EXPECT_NE(header.find("NMT"), std::string::npos) << header;
  EXPECT_EQ(header.find("AGE"), std::string::npos) << header;  // the least important of the 80 set
}

TEST_F(DemoFleet, TheScenarioLineShowsCycleClockCountsAndStepUnderTheBuses) {
  const RenderSettings settings{.width = 80, .height = 40, .color = false, .now = kNow};
  const auto lines = Lines(RenderFrame(view_, settings));
  const auto scenario = std::find_if(lines.begin(), lines.end(),
                                     [](const std::string& l) { return l.rfind("scenario demo", 0) == 0; });
  ASSERT_NE(scenario, lines.end());
  EXPECT_EQ(*scenario, "scenario demo  cycle 2  t=82.3 s  21 passed  1 FAILED  5 pending  step off-psu");
  const auto bus =
      std::find_if(lines.begin(), lines.end(), [](const std::string& l) { return l.rfind("can1", 0) == 0; });
  EXPECT_LT(bus - lines.begin(), scenario - lines.begin()) << "under the bus lines";
  const auto can0 =
      std::find_if(lines.begin(), lines.end(), [](const std::string& l) { return l.rfind("can0", 0) == 0; });
  ASSERT_NE(can0, lines.end());
  EXPECT_NE(can0->find("FAULTS #3 bus-off node 34"), std::string::npos) << *can0;  // faults before top ids
}

TEST_F(DemoFleet, AStepNameIsShownWholeOrNotAtAll) {
  view_.Apply(telemetry::ScenarioStatusSample{.source = "topologies/demo.textproto",
                                              .scenario = "demo",
                                              .scenario_time_s = 51.5,
                                              .cycle = 2,
                                              .running = true,
                                              .passed = 13,
                                              .pending = 12,
                                              .step = "psu-34-bus-off-preop",
                                              .publish_period = 1s},
              At(kNow - 100ms), nullptr);
  RenderSettings settings{.width = 80, .height = 40, .color = false, .now = kNow};
  auto lines = Lines(RenderFrame(view_, settings));
  auto scenario = std::find_if(lines.begin(), lines.end(),
                               [](const std::string& l) { return l.rfind("scenario demo", 0) == 0; });
  ASSERT_NE(scenario, lines.end());
  EXPECT_EQ(*scenario, "scenario demo  cycle 2  t=51.5 s  13 passed  0 failed  12 pending");
  settings.width = 100;
  lines = Lines(RenderFrame(view_, settings));
  scenario = std::find_if(lines.begin(), lines.end(),
                          [](const std::string& l) { return l.rfind("scenario demo", 0) == 0; });
  ASSERT_NE(scenario, lines.end());
  EXPECT_EQ(*scenario,
            "scenario demo  cycle 2  t=51.5 s  13 passed  0 failed  12 pending  step psu-34-bus-off-preop");
}

TEST_F(DemoFleet, VerdictsAreRecentEventsAndFailuresAreRed) {
  RenderSettings settings{.width = 80, .height = 40, .color = false, .event_lines = 10, .now = kNow};
  auto lines = Lines(RenderFrame(view_, settings));
  const auto failed = std::find_if(lines.begin(), lines.end(), [](const std::string& l) {
    return l.find("FAIL quad-6-emcy (cycle 2): EMCY 8130h from quad-6") != std::string::npos;
  });
  ASSERT_NE(failed, lines.end()) << RenderFrame(view_, settings);
  EXPECT_EQ(failed->compare(failed->size() - 3, 3, "..."), 0) << *failed;  // cut at a word, and says so
  EXPECT_NE(std::find_if(
                lines.begin(), lines.end(),
                [](const std::string& l) { return l.find("pass pout-on (cycle 2)") != std::string::npos; }),
            lines.end());

  settings.color = true;
  lines = Lines(RenderFrame(view_, settings));
  const auto red = std::find_if(lines.begin(), lines.end(), [](const std::string& l) {
    return l.find("FAIL quad-6-emcy") != std::string::npos;
  });
  ASSERT_NE(red, lines.end());
  EXPECT_EQ(red->rfind("\x1b[31;1m", 0), 0u) << *red;
}

TEST_F(DemoFleet, TheTitleFitsAndKeepsTheCounts) {
  const RenderSettings settings{.width = 80, .height = 40, .color = false, .now = kNow};
  const std::string title = Lines(RenderFrame(view_, settings)).front();
  EXPECT_LE(title.size(), 80u);
  EXPECT_NE(title.find("10 nodes on 2 buses, 2 faulted"), std::string::npos) << title;
}

TEST_F(DemoFleet, FilterByNameOrNewStateWord) {
  EXPECT_EQ(SelectRows(view_, {.text = "psu-34"}, SortKey::kBusNode, false, kNow).size(), 1u);
  EXPECT_EQ(SelectRows(view_, {.state = "pre-operational"}, SortKey::kBusNode, false, kNow).size(), 1u);
  EXPECT_EQ(SelectRows(view_, {.state = "PREOP"}, SortKey::kBusNode, false, kNow).size(), 1u);
  EXPECT_EQ(SelectRows(view_, {.state = "error-passive"}, SortKey::kBusNode, false, kNow).size(), 1u);
  const auto by_name = SelectRows(view_, {}, SortKey::kName, false, kNow);
  ASSERT_FALSE(by_name.empty());
  EXPECT_EQ(by_name.front()->status.name, "datalogger");
}

TEST_F(DemoFleet, ANodeWithoutANameShowsADash) {
  view_.Apply(NodeStatusSample{.bus = "can1", .node_id = 99, .device = "fake", .publish_period = 1s},
              At(kNow - 100ms), nullptr);
  const RenderSettings settings{.width = 80, .height = 40, .color = false, .now = kNow};
  const auto lines = Lines(RenderFrame(view_, settings));
  EXPECT_NE(std::find_if(lines.begin(), lines.end(),
                         [](const std::string& l) {
                           return l.rfind("  -  ", 0) == 0 && l.find(" 99 ") != std::string::npos;
                         }),
            lines.end());
}

TEST(NodeDetailWords, BoolsAndEnumsShowTheirWordsNotNumbers) {
  FleetView view(kNow - 10s);
  view.Apply(NodeStatusSample{.bus = "can0",
                              .node_id = 34,
                              .device = "power-supply-24v-350w",
                              .name = "psu-34",
                              .publish_period = 1s},
             At(kNow - 1s), nullptr);
  IoSnapshotSample io{.bus = "can0", .node_id = 34};
  io.inputs = {{"ENABLE.level", 1, "", "high"}, {"LOAD.resistance_ohm", 4, "ohm", ""}};
  io.outputs = {{"PS.state", 1, "", "on"}, {"PS.output_on", 1, "", "true"}};
  view.Apply(io, At(kNow - 1s), nullptr);
  const RenderSettings settings{
      .width = 80, .color = false, .now = kNow, .selected = NodeKey{"can0", 34}, .detail = true};
  const auto frame = RenderFrame(view, settings);
  const auto lines = Lines(frame);
  EXPECT_NE(frame.find("can0 #34 psu-34"), std::string::npos) << frame;
  const auto state = std::find_if(lines.begin(), lines.end(), [](const std::string& l) {
    return l.find("PS.state") != std::string::npos;
  });
  ASSERT_NE(state, lines.end());
  EXPECT_NE(state->find(" on"), std::string::npos) << *state;
  EXPECT_EQ(state->find(" 1"), std::string::npos) << *state;
  EXPECT_NE(frame.find("high"), std::string::npos);
  EXPECT_NE(frame.find("true"), std::string::npos);
  EXPECT_NE(frame.find("4 ohm"), std::string::npos);
  for (const auto& line : lines)
    EXPECT_LE(line.size(), 80u) << line;
}

TEST(TextFit, LinesAreCutAtAWordWithAMarkerCellsWithATilde) {
  EXPECT_EQ(FitLine("heartbeat-loss of quad-5 on can0 (to all receivers)", 30),
            "heartbeat-loss of quad-5 on...");
  EXPECT_EQ(FitLine("short", 30), "short");
  EXPECT_EQ(FitLine("averyveryverylongsingleword", 10), "averyve...");  // one word: cut, but marked
  EXPECT_EQ(FitCell("power-supply-24v-350w", 10), "power-sup~");
  EXPECT_EQ(FitCell("12", 4, true), "  12");
  EXPECT_EQ(FitCell("ab", 4), "ab  ");
}

TEST(TextFit, PartsAreKeptByPriorityInTheirOrder) {
  const std::vector<Part> parts{{"aaaa", 0}, {"bbbbbbbbbb", 2}, {"cc", 1}, {"dd dd dd dd dd", 3, true}};
  auto kept = FitParts(parts, 14);  // "bbbbbbbbbb" does not fit, nor 12 characters of the cuttable part
  std::string joined = JoinParts(kept, false);
  EXPECT_EQ(joined, "aaaa  cc");
  kept = FitParts(parts, 40);
  EXPECT_EQ(JoinParts(kept, false), "aaaa  bbbbbbbbbb  cc  dd dd dd dd dd");
  kept = FitParts(parts, 34);
  EXPECT_EQ(JoinParts(kept, false), "aaaa  bbbbbbbbbb  cc  dd dd dd...");
  kept = FitParts(parts, 31);  // 9 characters left: a cut part would say little more than "..."
  EXPECT_EQ(JoinParts(kept, false), "aaaa  bbbbbbbbbb  cc");
}

}  // namespace
}  // namespace canfleet::tools
