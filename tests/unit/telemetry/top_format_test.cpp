// `canfleet top`: row selection, ordering, paging and the rendered screen.
#include "tools/telemetry/top_format.hpp"

#include "tests/support/text_lines.hpp"
#include "tools/telemetry/node_detail.hpp"

#include <gtest/gtest.h>

#include <sstream>

namespace canfleet::tools {
namespace {

using namespace std::chrono_literals;
using telemetry::ControllerState;
using telemetry::NmtState;

const WallTime kNow = WallTime(1'700'000'000s);

SampleMeta At(WallTime t) {
  return {.source_time = t};
}

NodeStatusSample Status(const std::string& bus, std::uint8_t node, NmtState state = NmtState::kOperational) {
  NodeStatusSample s;
  s.bus = bus;
  s.node_id = node;
  s.device = node % 2 ? "quad-controller" : "valve-12in12out";
  s.nmt_state = state;
  s.publish_period = 1s;
  s.uptime = 3723s;
  return s;
}

std::vector<int> Ids(const std::vector<const NodeRow*>& rows) {
  std::vector<int> ids;
  for (const NodeRow* row : rows)
    ids.push_back(row->status.node_id);
  return ids;
}

using ::canfleet::test::Lines;

class TopFormat : public ::testing::Test {
 protected:
  void SetUp() override {
    view_.Apply(Status("can0", 3), At(kNow - 100s), nullptr);
    view_.Apply(Status("can0", 1, NmtState::kPreOperational), At(kNow - 100s), nullptr);
    NodeStatusSample busoff = Status("can1", 2);
    busoff.controller_state = ControllerState::kBusOff;
    busoff.tec = 256;
    view_.Apply(Status("can1", 2), At(kNow - 100s), nullptr);
    view_.Apply(busoff, At(kNow - 1s), nullptr);  // changed just now
    NodeStatusSample passive = Status("can0", 4, NmtState::kStopped);
    passive.controller_state = ControllerState::kErrorPassive;
    passive.tec = 130;
    view_.Apply(passive, At(kNow - 50s), nullptr);
    // Periodic republications since (no change): every node is current, not stale.
    const auto nodes = view_.nodes();
    for (const auto& [key, row] : nodes)
      view_.Apply(row.status, At(kNow - 500ms), nullptr);
  }
  FleetView view_{kNow - 200s};
};

TEST_F(TopFormat, DefaultOrderIsBusThenNode) {
  EXPECT_EQ(Ids(SelectRows(view_, {}, SortKey::kBusNode, false, kNow)), (std::vector<int>{1, 3, 4, 2}));
  EXPECT_EQ(Ids(SelectRows(view_, {}, SortKey::kBusNode, true, kNow)), (std::vector<int>{2, 4, 3, 1}));
}

TEST_F(TopFormat, SortByStateHealthiestFirstAndByErrorsWorstFirst) {
  EXPECT_EQ(Ids(SelectRows(view_, {}, SortKey::kState, false, kNow)), (std::vector<int>{3, 1, 4, 2}));
  EXPECT_EQ(Ids(SelectRows(view_, {}, SortKey::kErrors, false, kNow)).front(), 2);  // bus-off
  EXPECT_EQ(Ids(SelectRows(view_, {}, SortKey::kLastChange, false, kNow)).front(), 2);
}

TEST_F(TopFormat, FiltersByBusStateAndText) {
  EXPECT_EQ(Ids(SelectRows(view_, {.bus = "can1"}, SortKey::kBusNode, false, kNow)), (std::vector<int>{2}));
  EXPECT_EQ(Ids(SelectRows(view_, {.state = "preop"}, SortKey::kBusNode, false, kNow)),
            (std::vector<int>{1}));
  EXPECT_EQ(Ids(SelectRows(view_, {.state = "passive"}, SortKey::kBusNode, false, kNow)),
            (std::vector<int>{4}));
  EXPECT_EQ(Ids(SelectRows(view_, {.state = "fault"}, SortKey::kBusNode, false, kNow)),
            (std::vector<int>{2}));
  EXPECT_EQ(Ids(SelectRows(view_, {.state = "ok"}, SortKey::kBusNode, false, kNow)),
            (std::vector<int>{1, 3, 4}));
  EXPECT_EQ(Ids(SelectRows(view_, {.text = "VALVE"}, SortKey::kBusNode, false, kNow)),
            (std::vector<int>{4, 2}));
  EXPECT_EQ(Ids(SelectRows(view_, {.text = "can0 #3"}, SortKey::kBusNode, false, kNow)),
            (std::vector<int>{3}));
}

TEST_F(TopFormat, StateFilterWordsAreValidated) {
  EXPECT_TRUE(IsValidStateFilter("pre-operational"));
  EXPECT_TRUE(IsValidStateFilter("error-passive"));
  EXPECT_TRUE(IsValidStateFilter("OPER"));  // the short words of old still work
  EXPECT_TRUE(IsValidStateFilter("bus-off"));
  EXPECT_TRUE(IsValidStateFilter(""));
  EXPECT_FALSE(IsValidStateFilter("running"));
}

TEST_F(TopFormat, PlainFrameHasNoEscapesAndOneLinePerNode) {
  RenderSettings settings{.color = false, .now = kNow};
  const std::string frame = RenderFrame(view_, settings);
  EXPECT_EQ(frame.find('\x1b'), std::string::npos);
  const auto lines = Lines(frame);
  EXPECT_NE(lines[0].find("4 nodes on 2 buses, 1 faulted"), std::string::npos);
  const auto buses = std::count_if(lines.begin(), lines.end(), [](const std::string& l) {
    return l.rfind("can0 ", 0) == 0 || l.rfind("can1 ", 0) == 0;
  });
  EXPECT_EQ(buses, 2);
  const auto rows = std::count_if(lines.begin(), lines.end(), [](const std::string& l) {
    return l.rfind("  ", 0) == 0 &&
           (l.find(" can0 ") != std::string::npos || l.find(" can1 ") != std::string::npos);
  });
  EXPECT_EQ(rows, 4);
  EXPECT_NE(frame.find("bus-off"), std::string::npos);
  EXPECT_NE(frame.find("1:02:03"), std::string::npos);  // uptime 3723 s
}

TEST_F(TopFormat, ColorFrameMarksFaultsRedAndFreshChangesReversed) {
  RenderSettings settings{.color = true, .now = kNow};
  const auto lines = Lines(RenderFrame(view_, settings));
  const auto row = std::find_if(lines.begin(), lines.end(),
                                [](const std::string& l) { return l.find("can1  2") != std::string::npos; });
  ASSERT_NE(row, lines.end());
  EXPECT_NE(row->find("\x1b[31m"), std::string::npos);  // red: bus-off
  EXPECT_NE(row->find("\x1b[1m"), std::string::npos);   // bold: changed within 5 s
  EXPECT_EQ(row->find("\x1b[7m"), std::string::npos);   // reverse video is the selection's alone
  const auto quiet = std::find_if(lines.begin(), lines.end(), [](const std::string& l) {
    return l.find("can0  3") != std::string::npos;
  });
  ASSERT_NE(quiet, lines.end());
  EXPECT_EQ(quiet->find('\x1b'), std::string::npos);  // healthy and quiet: plain
}

TEST_F(TopFormat, ArrowKeysMoveTheSelectionWithinTheShownRowsAndItIsMarked) {
  const auto rows = SelectRows(view_, {}, SortKey::kBusNode, false, kNow);  // 1, 3, 4 on can0; 2 on can1
  auto selected = MoveSelection(rows, std::nullopt, +1);                    // nothing yet: the first
  ASSERT_TRUE(selected);
  EXPECT_EQ(selected->node_id, 1);
  selected = MoveSelection(rows, selected, +1);
  EXPECT_EQ(selected->node_id, 3);
  EXPECT_EQ(MoveSelection(rows, selected, -5)->node_id, 1);            // held at the top
  EXPECT_EQ(MoveSelection(rows, selected, +10)->node_id, 2);           // and at the bottom
  EXPECT_EQ(MoveSelection(rows, NodeKey{"can9", 1}, +1)->node_id, 1);  // filtered out: the first
  EXPECT_FALSE(MoveSelection({}, selected, +1));
  EXPECT_EQ(PageOf(rows, {"can1", 2}, 2), 1);
  EXPECT_FALSE(PageOf(rows, {"can9", 1}, 2));

  // Without colors the selected row starts with "> " (issue 29: a trailing "<" was cut off at 80
  // columns); every other row starts with two blanks.
  RenderSettings settings{.width = 80, .color = false, .now = kNow, .selected = NodeKey{"can0", 3}};
  auto lines = Lines(RenderFrame(view_, settings));
  const auto marked =
      std::count_if(lines.begin(), lines.end(), [](const std::string& l) { return l.rfind("> ", 0) == 0; });
  EXPECT_EQ(marked, 1);
  const auto row =
      std::find_if(lines.begin(), lines.end(), [](const std::string& l) { return l.rfind("> ", 0) == 0; });
  ASSERT_NE(row, lines.end());
  EXPECT_NE(row->find("can0  3"), std::string::npos) << *row;
  EXPECT_NE(lines.back().find("Enter detail"), std::string::npos);  // the help line says how

  // In color it is in reverse video as well, across the whole width (not only underlined).
  settings.color = true;
  lines = Lines(RenderFrame(view_, settings));
  const auto colored = std::find_if(lines.begin(), lines.end(), [](const std::string& l) {
    return l.find("> ") != std::string::npos && l.find("can0  3") != std::string::npos;
  });
  ASSERT_NE(colored, lines.end());
  EXPECT_NE(colored->find("\x1b[7m"), std::string::npos);
  EXPECT_EQ(colored->find("\x1b[4m"), std::string::npos);
  const auto others = std::count_if(lines.begin(), lines.end(), [](const std::string& l) {
    return l.find("\x1b[7m") != std::string::npos;
  });
  EXPECT_EQ(others, 1);
}

class NodeDetail : public TopFormat {
 protected:
  void SetUp() override {
    TopFormat::SetUp();
    NodeStatusSample s = Status("can0", 6);
    s.device = "quad-controller";
    s.error_register = 0x01;
    s.heartbeat_producer_ms = 500;
    s.heartbeat_consumers = {{.node_id = 5,
                              .time_ms = 1500,
                              .state = telemetry::HeartbeatConsumerState::kTimedOut,
                              .last_state = NmtState::kOperational}};
    s.rpdo_count = 378;
    s.tpdo_count = 1512;
    view_.Apply(s, At(kNow - 500ms), nullptr);
    IoSnapshotSample io{.bus = "can0", .node_id = 6};
    io.inputs = {{"IN1.voltage_mV", 1200, "mV"}, {"IN1.level", 1, ""}};
    io.outputs = {
        {"OUT1.current_mA", 0, "mA"}, {"TEMP.temperature_C", 41.25, "C"}, {"OUT2.current_mA", 800, "mA"}};
    view_.Apply(io, At(kNow - 400ms), nullptr);
    view_.Apply(EmcySample{.bus = "can0",
                           .node_id = 6,
                           .emcy = {.code = 0x8130, .error_register = 0x01, .manufacturer = {5, 8, 0, 0, 0}}},
                At(kNow - 2s), nullptr);
    view_.Apply(EmcySample{.bus = "can0", .node_id = 6, .emcy = {.code = 0x0000}}, At(kNow - 60s), nullptr);
  }
  RenderSettings settings_{.color = false, .now = kNow, .selected = NodeKey{"can0", 6}, .detail = true};
};

TEST_F(NodeDetail, ShowsStatusCountersIoWithUnitsAndTheEmcysTheBusSawNewestFirst) {
  const std::string frame = RenderFrame(view_, settings_);
  EXPECT_EQ(frame.find('\x1b'), std::string::npos);
  EXPECT_NE(frame.find("can0 #6  quad-controller"), std::string::npos);
  EXPECT_NE(frame.find("error register (1001h) 01h"), std::string::npos);
  EXPECT_NE(frame.find("#5 timed-out (1500 ms, last operational)"), std::string::npos);
  EXPECT_NE(frame.find("378 received, 1512 sent"), std::string::npos);
  EXPECT_NE(frame.find("SIMULATED INPUTS (2)"), std::string::npos);
  EXPECT_NE(frame.find("SIMULATED OUTPUTS (3)"), std::string::npos);
  const auto lines = Lines(frame);
  const auto ain = std::find_if(lines.begin(), lines.end(),
                                [](const std::string& l) { return l.rfind("IN1.voltage_mV", 0) == 0; });
  ASSERT_NE(ain, lines.end());
  EXPECT_NE(ain->find("1200 mV"), std::string::npos);
  EXPECT_NE(ain->find("OUT1.current_mA"), std::string::npos);  // outputs beside the inputs
  EXPECT_NE(ain->find("0 mA"), std::string::npos);
  EXPECT_NE(frame.find("41.25 C"), std::string::npos);
  EXPECT_NE(frame.find("AS THE BUS SAW THEM"), std::string::npos);
  const auto heartbeat = frame.find("8130h  01h  05 08 00 00 00  ");
  const auto reset = frame.find("0000h  00h  00 00 00 00 00  ");
  ASSERT_NE(heartbeat, std::string::npos);
  ASSERT_NE(reset, std::string::npos);
  EXPECT_LT(heartbeat, reset);  // newest first
  // 1003h is not telemetry: the screen says where to read it instead of showing a guess.
  EXPECT_NE(frame.find("canfleet sdo read NODE 0x1003 1 u32"), std::string::npos);
  EXPECT_NE(lines.back().find("Esc back"), std::string::npos);
}

TEST_F(NodeDetail, FitsTheScreenAndKeepsTheNewestEmcysWhenShort) {
  for (int i = 0; i < 20; ++i)
    view_.Apply(
        EmcySample{.bus = "can0", .node_id = 6, .emcy = {.code = static_cast<std::uint16_t>(0x2300 + i)}},
        At(kNow - 1s + std::chrono::milliseconds(i)), nullptr);
  settings_.width = 60;
  settings_.height = 20;
  const auto lines = Lines(RenderFrame(view_, settings_));
  EXPECT_LE(static_cast<int>(lines.size()), settings_.height);
  for (const auto& line : lines)
    EXPECT_LE(static_cast<int>(line.size()), settings_.width);
  const std::string frame = RenderFrame(view_, settings_);
  EXPECT_NE(frame.find("2313h"), std::string::npos);  // the newest is shown
  EXPECT_EQ(frame.find("0000h"), std::string::npos);  // the oldest gave way
}

TEST_F(NodeDetail, AnUnknownNodeOrNoIoSaysSo) {
  settings_.selected = NodeKey{"can7", 9};
  EXPECT_NE(RenderFrame(view_, settings_).find("no telemetry of can7 #9"), std::string::npos);
  settings_.selected = NodeKey{"can0", 3};  // a status, no IoSnapshot
  EXPECT_NE(RenderFrame(view_, settings_).find("simulated I/O: none published"), std::string::npos);
  EXPECT_NE(RenderFrame(view_, settings_).find("(none since the Emcy topic's history began)"),
            std::string::npos);
  settings_.detail = false;  // back: the table
  EXPECT_NE(RenderFrame(view_, settings_).find("LAST EMCY"), std::string::npos);
}

TEST(TopText, IoValuesAreShortAndExact) {
  EXPECT_EQ(FormatIoValue(1200), "1200");
  EXPECT_EQ(FormatIoValue(-40), "-40");
  EXPECT_EQ(FormatIoValue(23.5), "23.5");
  EXPECT_EQ(FormatIoValue(4.75), "4.75");
  EXPECT_EQ(FormatIoValue(0.1234), "0.123");
}

TEST(TopPaging, A127NodeBusPagesWithinTheScreen) {
  FleetView view(kNow - 10s);
  for (std::uint8_t id = 1; id <= 127; ++id)
    view.Apply(Status("can0", id), At(kNow - 1s), nullptr);
  RenderSettings settings{.width = 120, .height = 40, .color = false, .now = kNow};
  const int per_page = RowsPerPage(settings, StatusLines(view, {}));
  const int pages = PageCount(127, per_page);
  EXPECT_EQ(pages, (127 + per_page - 1) / per_page);
  std::set<std::string> seen;
  for (int page = 0; page < pages; ++page) {
    settings.page = page;
    const auto lines = Lines(RenderFrame(view, settings));
    EXPECT_LE(static_cast<int>(lines.size()), settings.height);
    for (const auto& line : lines) {
      EXPECT_LE(static_cast<int>(line.size()), settings.width);
      if (line.find(" can0 ") != std::string::npos && line.find("nodes 127") == std::string::npos)
        seen.insert(line.substr(0, 24));
    }
  }
  EXPECT_EQ(seen.size(), 127u);  // every node on exactly one page
  settings.page = 99;            // past the end: the last page
  EXPECT_NE(RenderFrame(view, settings).find(" page " + std::to_string(pages) + "/"), std::string::npos);
}

TEST(TopPaging, OneScreenShows127NodesWhenTallEnough) {
  FleetView view(kNow - 10s);
  for (std::uint8_t id = 1; id <= 127; ++id)
    view.Apply(Status("can0", id), At(kNow - 1s), nullptr);
  RenderSettings settings{.height = 140, .color = false, .now = kNow};
  EXPECT_NE(RenderFrame(view, settings).find("page 1/1"), std::string::npos);
}

TEST(TopText, UptimeAndAgeFormats) {
  EXPECT_EQ(FormatUptime(3723s), "1:02:03");
  EXPECT_EQ(FormatUptime(std::chrono::hours(76)), "3d04h");
  EXPECT_EQ(FormatAge(400ms), "0.4s");
  EXPECT_EQ(FormatAge(42s), "42s");
  EXPECT_EQ(FormatAge(5min), "5m");
  EXPECT_EQ(FormatAge(3h), "3h");
}

TEST(TopText, SortKeysCycleAndParse) {
  SortKey key = SortKey::kBusNode;
  std::set<SortKey> seen;
  for (int i = 0; i < 6; ++i) {
    seen.insert(key);
    EXPECT_EQ(ParseSortKey(ToString(key)), key);
    key = NextSortKey(key);
  }
  EXPECT_EQ(seen.size(), 6u);
  EXPECT_EQ(key, SortKey::kBusNode);
}

}  // namespace
}  // namespace canfleet::tools

namespace canfleet::tools {
namespace {

// Virtual time (orchestrator/broker/README.md "Virtual time"): a bus line shows the simulated time
// and the factor achieved, so a person watching knows what the clocks mean.
TEST(TopFormatVirtualTime, ABusInVirtualTimeShowsSimulatedTimeAndTheFactor) {
  FleetView view{kNow - 200s};
  telemetry::BusStatsSample stats;
  stats.bus = "can0";
  stats.bitrate = 250'000;
  stats.mode = "virtual";
  stats.simulated_s = 3600.04;
  stats.speed_factor = 70.4F;
  view.Apply(stats, At(kNow - 1s), nullptr);
  RenderSettings settings{.color = false, .now = kNow};
  const std::string frame = RenderFrame(view, settings);
  EXPECT_NE(frame.find("virtual"), std::string::npos) << frame;
  EXPECT_NE(frame.find("t=3600.0 s (70x)"), std::string::npos) << frame;
}

}  // namespace
}  // namespace canfleet::tools
