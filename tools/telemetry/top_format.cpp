#include "tools/telemetry/top_format.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <set>
#include <tuple>

#include "tools/telemetry/event_format.hpp"
#include "tools/telemetry/node_detail.hpp"
#include "tools/telemetry/text_fit.hpp"

namespace canfleet::tools {

using telemetry::ControllerState;
using telemetry::HeartbeatConsumerState;
using telemetry::NmtState;

const char* ToString(SortKey key) {
  switch (key) {
    case SortKey::kBusNode:
      return "node";
    case SortKey::kState:
      return "state";
    case SortKey::kErrors:
      return "errors";
    case SortKey::kLastChange:
      return "change";
    case SortKey::kDevice:
      return "device";
    case SortKey::kName:
      return "name";
  }
  return "?";
}

std::optional<SortKey> ParseSortKey(std::string_view text) {
  for (auto key : {SortKey::kBusNode, SortKey::kName, SortKey::kState, SortKey::kErrors, SortKey::kLastChange,
                   SortKey::kDevice}) {
    if (text == ToString(key)) return key;
  }
  return std::nullopt;
}

SortKey NextSortKey(SortKey key) {
  switch (key) {
    case SortKey::kBusNode:
      return SortKey::kName;
    case SortKey::kName:
      return SortKey::kState;
    case SortKey::kState:
      return SortKey::kErrors;
    case SortKey::kErrors:
      return SortKey::kLastChange;
    case SortKey::kLastChange:
      return SortKey::kDevice;
    case SortKey::kDevice:
      return SortKey::kBusNode;
  }
  return SortKey::kBusNode;
}

namespace {

std::string Lower(std::string_view text) {
  std::string out(text);
  for (char& c : out)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

/// Orders states from healthiest to worst, for sorting by state.
int StateRank(const NodeRow& row) {
  if (!row.alive) return 6;
  if (row.status.controller_state == ControllerState::kBusOff) return 5;
  if (row.status.controller_state == ControllerState::kErrorPassive) return 4;
  if (!row.status.nmt_state) return 3;
  switch (*row.status.nmt_state) {
    case NmtState::kOperational:
      return 0;
    case NmtState::kPreOperational:
      return 1;
    case NmtState::kStopped:
      return 2;
    case NmtState::kInitialising:
      return 3;
  }
  return 3;
}

int TimedOutConsumers(const NodeRow& row) {
  return static_cast<int>(
      std::count_if(row.status.heartbeat_consumers.begin(), row.status.heartbeat_consumers.end(),
                    [](const auto& c) { return c.state == HeartbeatConsumerState::kTimedOut; }));
}

/// A severity for sorting by errors: faults first, then counters.
std::tuple<int, int, int, int> ErrorRank(const NodeRow& row, WallTime now) {
  return {IsFaulted(row, now) ? 1 : 0, row.status.error_register != 0 ? 1 : 0, TimedOutConsumers(row),
          row.status.tec + row.status.rec};
}

enum class Severity { kNormal, kWarning, kFault };

Severity RowSeverity(const NodeRow& row, WallTime now) {
  if (IsFaulted(row, now)) return Severity::kFault;
  if (row.status.controller_state == ControllerState::kErrorPassive ||
      row.status.nmt_state != std::optional<NmtState>(NmtState::kOperational) || row.status.tec > 0 ||
      row.status.rec > 0) {
    return Severity::kWarning;
  }
  return Severity::kNormal;
}

constexpr const char* kReset = "\x1b[0m";
constexpr const char* kBold = "\x1b[1m";
constexpr const char* kReverse = "\x1b[7m";
constexpr const char* kRed = "\x1b[31m";
constexpr const char* kGreen = "\x1b[32m";
constexpr const char* kYellow = "\x1b[33m";
constexpr const char* kMagenta = "\x1b[35m";
constexpr const char* kDim = "\x1b[2m";
constexpr const char* kRedBold = "\x1b[31;1m";

std::string Printf(const char* format, auto... args) {
  char text[512];
  std::snprintf(text, sizeof text, format, args...);
  return text;
}

std::string Consumers(const NodeRow& row) {
  const auto& consumers = row.status.heartbeat_consumers;
  if (consumers.empty()) return "-";
  const auto active = std::count_if(consumers.begin(), consumers.end(),
                                    [](const auto& c) { return c.state == HeartbeatConsumerState::kActive; });
  std::string text = std::to_string(active) + "/" + std::to_string(consumers.size());
  if (const int lost = TimedOutConsumers(row); lost > 0) text += " !" + std::to_string(lost);
  return text;
}

/// The NMT column: the state's word, or what became of the node.
std::string NmtCell(const NodeRow& row, WallTime now) {
  if (!row.alive) return row.disposed ? "LEFT" : "LOST";
  if (IsStale(row, now)) return "STALE";
  return telemetry::StateName(row.status.nmt_state);
}

/// One column of the node table.
struct Column {
  const char* header;
  int priority;        ///< lower is kept first when the width is short
  bool right = false;  ///< right-aligned (numbers)
  int max_width = 0;   ///< a longer cell is cut (ending in "~"); 0: no limit
  std::string (*cell)(const NodeRow&, WallTime);
};

// Display order. At 80 columns the first ten by priority fit: name, bus, id, NMT, controller,
// TEC/REC, error register, heartbeat consumers, last EMCY, age; wider screens add the device,
// the heartbeat producer time, the PDO counters and the uptime.
const std::array<Column, 16> kColumns{{
    {"NODE", 0, false, 16,
     [](const NodeRow& r, WallTime) { return r.status.name.empty() ? std::string("-") : r.status.name; }},
    {"BUS", 1, false, 15, [](const NodeRow& r, WallTime) { return r.status.bus; }},
    {"ID", 2, true, 3, [](const NodeRow& r, WallTime) { return std::to_string(r.status.node_id); }},
    {"DEVICE", 10, false, 21, [](const NodeRow& r, WallTime) { return r.status.device; }},
    {"NMT", 3, false, 0, [](const NodeRow& r, WallTime now) { return NmtCell(r, now); }},
    {"CONTROLLER", 4, false, 0,
     [](const NodeRow& r, WallTime) { return std::string(telemetry::StateName(r.status.controller_state)); }},
    {"TEC", 5, true, 3, [](const NodeRow& r, WallTime) { return std::to_string(r.status.tec); }},
    {"REC", 5, true, 3, [](const NodeRow& r, WallTime) { return std::to_string(r.status.rec); }},
    {"ERR", 6, false, 3, [](const NodeRow& r, WallTime) { return Printf("%02Xh", r.status.error_register); }},
    {"HB ms", 11, true, 5,
     [](const NodeRow& r, WallTime) { return std::to_string(r.status.heartbeat_producer_ms); }},
    {"CONS", 7, false, 8, [](const NodeRow& r, WallTime) { return Consumers(r); }},
    {"RPDO", 12, true, 10, [](const NodeRow& r, WallTime) { return std::to_string(r.status.rpdo_count); }},
    {"TPDO", 12, true, 10, [](const NodeRow& r, WallTime) { return std::to_string(r.status.tpdo_count); }},
    {"UPTIME", 13, true, 8, [](const NodeRow& r, WallTime) { return FormatUptime(r.status.uptime); }},
    {"LAST EMCY", 8, false, 12,
     [](const NodeRow& r, WallTime now) {
       const auto& e = r.status.last_emcy;
       if (!e) return std::string("-");
       std::string text = Printf("%04Xh", e->code);
       if (r.last_emcy) text += " " + FormatAge(now - r.last_emcy_time);
       return text;
     }},
    {"AGE", 9, true, 4, [](const NodeRow& r, WallTime now) { return FormatAge(now - r.last_sample); }},
}};

/// The selected row starts with this marker, plain or in color; other rows with blanks.
constexpr std::string_view kMarker = "> ";

struct Layout {
  std::vector<std::size_t> columns;  ///< indices into kColumns, display order
  std::vector<int> widths;           ///< parallel to columns
};

/// Which columns fit in `width` (after the marker), most important first, each as wide as its
/// header or its widest cell among `rows`.
Layout ChooseColumns(const std::vector<const NodeRow*>& rows, WallTime now, int width) {
  std::array<int, kColumns.size()> widths{};
  for (std::size_t c = 0; c < kColumns.size(); ++c) {
    std::size_t w = std::string_view(kColumns[c].header).size();
    for (const NodeRow* row : rows)
      w = std::max(w, kColumns[c].cell(*row, now).size());
    if (kColumns[c].max_width > 0)
      w = std::min(w, std::max<std::size_t>(std::string_view(kColumns[c].header).size(),
                                            static_cast<std::size_t>(kColumns[c].max_width)));
    widths[c] = static_cast<int>(w);
  }
  std::array<std::size_t, kColumns.size()> order{};
  for (std::size_t c = 0; c < order.size(); ++c)
    order[c] = c;
  std::stable_sort(order.begin(), order.end(),
                   [](std::size_t a, std::size_t b) { return kColumns[a].priority < kColumns[b].priority; });
  std::array<bool, kColumns.size()> chosen{};
  int used = static_cast<int>(kMarker.size());
  bool first = true;
  for (std::size_t i = 0; i < order.size();) {
    // Columns of one priority (TEC and REC) go together or not at all.
    std::size_t j = i;
    int need = 0;
    for (; j < order.size() && kColumns[order[j]].priority == kColumns[order[i]].priority; ++j) {
      need += widths[order[j]] + (first && j == i ? 0 : 1);
    }
    if (width <= 0 || used + need <= width) {
      for (std::size_t k = i; k < j; ++k)
        chosen[order[k]] = true;
      used += need;
      first = false;
    }
    i = j;
  }
  Layout layout;
  for (std::size_t c = 0; c < kColumns.size(); ++c) {
    if (!chosen[c]) continue;
    layout.columns.push_back(c);
    layout.widths.push_back(widths[c]);
  }
  return layout;
}

std::string TableLine(const Layout& layout, bool selected, auto text_of) {
  std::string line(selected ? kMarker : std::string_view("  "));
  for (std::size_t i = 0; i < layout.columns.size(); ++i) {
    const Column& column = kColumns[layout.columns[i]];
    if (i > 0) line += ' ';
    line += FitCell(text_of(column), layout.widths[i], column.right);
  }
  while (!line.empty() && line.back() == ' ')
    line.pop_back();
  return line;
}

std::string NodeLine(const Layout& layout, const NodeRow& row, WallTime now, bool selected) {
  return TableLine(layout, selected, [&](const Column& column) { return column.cell(row, now); });
}

std::string HeaderLine(const Layout& layout) {
  return TableLine(layout, false, [](const Column& column) { return std::string(column.header); });
}

std::vector<Part> BusParts(const std::string& name, const BusRow& bus, int node_count) {
  std::vector<Part> parts;
  parts.push_back({name, 0});
  if (bus.stats) {
    const auto& s = *bus.stats;
    parts.push_back({Printf("%u kbit/s", s.bitrate / 1000), 1});
    parts.push_back({s.mode, 7});
    parts.push_back({Printf("load %.1f%%", static_cast<double>(s.load_percent)), 2});
    if (s.mode == "virtual")
      parts.push_back({Printf("t=%.1f s (%.0fx)", s.simulated_s, static_cast<double>(s.speed_factor)), 2});
    parts.push_back({Printf("%.0f fr/s", static_cast<double>(s.frames_per_second)), 4});
    parts.push_back({Printf("err %llu", static_cast<unsigned long long>(s.error_frames)), 5});
  } else {
    parts.push_back({"(no bus statistics)", 1});
  }
  parts.push_back({Printf("nodes %d", node_count), 6});
  if (bus.stats) parts.push_back({Printf("ports %u", bus.stats->node_count), 8});
  if (!bus.active_faults.empty()) {
    std::string faults = "FAULTS";
    for (const auto& [id, fault] : bus.active_faults) {
      faults += Printf(" #%u %s", id, fault.kind.c_str());
      if (fault.target_node != 0) faults += Printf(" node %u", fault.target_node);
    }
    parts.push_back({faults, 3, true, kRedBold});
  }
  if (bus.stats && !bus.stats->top_cob_ids.empty()) {
    std::string top = "top";
    const auto& ids = bus.stats->top_cob_ids;
    for (std::size_t i = 0; i < ids.size() && i < 4; ++i)
      top += Printf(" %03Xh:%.0f", ids[i].cob_id, static_cast<double>(ids[i].frames_per_second));
    parts.push_back({top, 9, true});
  }
  return parts;
}

/// "scenario demo  cycle 2  t=45.2 s  12 passed  1 FAILED  4 pending  step cut-hb".
std::vector<Part> ScenarioParts(const ScenarioRow& row, WallTime now) {
  const auto& s = row.status;
  std::vector<Part> parts;
  parts.push_back({"scenario " + (s.scenario.empty() ? s.source : s.scenario), 0, true, kBold});
  parts.push_back({Printf("cycle %u", s.cycle), 4});
  parts.push_back({Printf("t=%.1f s", s.scenario_time_s), 1});
  if (s.time_mode == "virtual") parts.push_back({"virtual", 6});
  parts.push_back({Printf("%u passed", s.passed), 2, false, s.passed > 0 ? kGreen : ""});
  parts.push_back({Printf("%u %s", s.failed, s.failed > 0 ? "FAILED" : "failed"), 2, false,
                   s.failed > 0 ? kRedBold : ""});
  if (s.skipped > 0) parts.push_back({Printf("%u skipped", s.skipped), 2, false, kYellow});
  parts.push_back({Printf("%u pending", s.pending), 2});
  if (IsStale(row, now))
    parts.push_back({"(no news for " + FormatAge(now - row.last_sample) + ")", 1, false, kYellow});
  else if (!s.running && s.cycle > 0)
    parts.push_back({"done", 5});
  // A step's name is kept whole or left out: half a name says nothing.
  if (!s.step.empty()) parts.push_back({"step " + s.step, 3});
  return parts;
}

}  // namespace

namespace {

/// The state filter's word for a node's state, and the short words scripts used before issue 29.
bool StateMatches(const std::string& word, const NodeRow& row) {
  const auto& s = row.status;
  static constexpr std::array<std::pair<std::string_view, std::string_view>, 6> kOldWords{{
      {"oper", "operational"},
      {"preop", "pre-operational"},
      {"stop", "stopped"},
      {"init", "initialising"},
      {"active", "error-active"},
      {"passive", "error-passive"},
  }};
  std::string_view w = word;
  for (const auto& [old, now] : kOldWords)
    if (w == old) w = now;
  return w == telemetry::StateName(s.controller_state) || w == telemetry::StateName(s.nmt_state);
}

}  // namespace

bool IsValidStateFilter(std::string_view state) {
  static constexpr std::array<std::string_view, 17> kWords{
      "operational",  "pre-operational", "stopped", "initialising", "unknown",
      "error-active", "error-passive",   "bus-off", "fault",        "ok",
      "oper",         "preop",           "stop",    "init",         "active",
      "passive",      "initializing"};
  const std::string lower = Lower(state);
  return state.empty() || std::find(kWords.begin(), kWords.end(), lower) != kWords.end();
}

bool Matches(const NodeRow& row, const TopFilter& filter, WallTime now) {
  const auto& s = row.status;
  if (!filter.bus.empty() && s.bus != filter.bus) return false;
  if (!filter.state.empty()) {
    std::string state = Lower(filter.state);
    if (state == "initializing") state = "initialising";
    if (state == "fault") {
      if (!IsFaulted(row, now)) return false;
    } else if (state == "ok") {
      if (IsFaulted(row, now)) return false;
    } else if (!StateMatches(state, row)) {
      return false;
    }
  }
  if (!filter.text.empty()) {
    const std::string haystack =
        Lower(s.bus + " #" + std::to_string(s.node_id) + " " + s.name + " " + s.device);
    if (haystack.find(Lower(filter.text)) == std::string::npos) return false;
  }
  return true;
}

std::vector<const NodeRow*> SelectRows(const FleetView& view, const TopFilter& filter, SortKey key,
                                       bool reverse, WallTime now) {
  std::vector<const NodeRow*> rows;
  for (const auto& [node_key, row] : view.nodes()) {
    if (Matches(row, filter, now)) rows.push_back(&row);
  }
  // The map already orders by (bus, node-id): a stable sort keeps that as the tie-break.
  const auto by = [&](auto rank) {
    std::stable_sort(rows.begin(), rows.end(),
                     [&](const NodeRow* a, const NodeRow* b) { return rank(*a) < rank(*b); });
  };
  switch (key) {
    case SortKey::kBusNode:
      break;
    case SortKey::kState:
      by([](const NodeRow& r) { return StateRank(r); });
      break;
    // Worst first: faults, error register, lost consumers, error counters.
    case SortKey::kErrors:
      by([&](const NodeRow& r) {
        auto [a, b, c, d] = ErrorRank(r, now);
        return std::make_tuple(-a, -b, -c, -d);
      });
      break;
    case SortKey::kLastChange:
      by([](const NodeRow& r) { return -r.last_change.time_since_epoch().count(); });
      break;
    case SortKey::kDevice:
      by([](const NodeRow& r) { return r.status.device; });
      break;
    case SortKey::kName:
      by([](const NodeRow& r) { return r.status.name; });
      break;
  }
  if (reverse) std::reverse(rows.begin(), rows.end());
  return rows;
}

int RowsPerPage(const RenderSettings& settings, int status_lines) {
  // title + bus and scenario lines + blank + column header ... + blank + "events" + event lines + help
  const int fixed = 1 + status_lines + 1 + 1 + 1 + 1 + settings.event_lines + 1;
  return std::max(1, settings.height - fixed);
}

int PageCount(std::size_t rows, int rows_per_page) {
  return std::max(1, static_cast<int>((rows + static_cast<std::size_t>(rows_per_page) - 1) /
                                      static_cast<std::size_t>(rows_per_page)));
}

std::string FormatUptime(std::chrono::milliseconds uptime) {
  const auto total = std::chrono::duration_cast<std::chrono::seconds>(uptime).count();
  if (total >= 86400)
    return Printf("%lldd%02lldh", static_cast<long long>(total / 86400),
                  static_cast<long long>(total % 86400 / 3600));
  return Printf("%lld:%02lld:%02lld", static_cast<long long>(total / 3600),
                static_cast<long long>(total % 3600 / 60), static_cast<long long>(total % 60));
}

std::string FormatAge(std::chrono::system_clock::duration age) {
  const double seconds = std::chrono::duration<double>(age).count();
  if (seconds < 0) return "0.0s";
  if (seconds < 10) return Printf("%.1fs", seconds);
  if (seconds < 120) return Printf("%.0fs", seconds);
  if (seconds < 7200) return Printf("%.0fm", seconds / 60);
  return Printf("%.0fh", seconds / 3600);
}

std::optional<NodeKey> MoveSelection(const std::vector<const NodeRow*>& rows,
                                     const std::optional<NodeKey>& current, int delta) {
  if (rows.empty()) return std::nullopt;
  const auto at = current ? std::find_if(rows.begin(), rows.end(),
                                         [&](const NodeRow* r) { return r->status.key() == *current; })
                          : rows.end();
  if (at == rows.end()) return rows.front()->status.key();
  const auto index =
      std::clamp<std::ptrdiff_t>(at - rows.begin() + delta, 0, static_cast<std::ptrdiff_t>(rows.size()) - 1);
  return rows[static_cast<std::size_t>(index)]->status.key();
}

std::optional<int> PageOf(const std::vector<const NodeRow*>& rows, const NodeKey& key, int rows_per_page) {
  for (std::size_t i = 0; i < rows.size(); ++i)
    if (rows[i]->status.key() == key) return static_cast<int>(i) / std::max(1, rows_per_page);
  return std::nullopt;
}

int StatusLines(const FleetView& view, const TopFilter& filter) {
  std::set<std::string> buses;
  for (const auto& [name, bus] : view.buses())
    buses.insert(name);
  for (const auto& [key, row] : view.nodes())
    buses.insert(key.bus);
  if (!filter.bus.empty()) buses = {filter.bus};
  return static_cast<int>(buses.size() + view.scenarios().size());
}

std::string RenderFrame(const FleetView& view, const RenderSettings& settings) {
  if (settings.detail && settings.selected) return RenderNodeDetail(view, *settings.selected, settings);
  const WallTime now = settings.now;
  const int width = settings.width;
  const auto rows = SelectRows(view, settings.filter, settings.sort, settings.reverse, now);

  // Buses: every bus that has statistics or nodes, unless filtered to one.
  std::map<std::string, int> bus_nodes;
  for (const auto& [name, bus] : view.buses())
    bus_nodes[name];
  for (const auto& [key, row] : view.nodes())
    ++bus_nodes[key.bus];
  if (!settings.filter.bus.empty())
    std::erase_if(bus_nodes, [&](const auto& b) { return b.first != settings.filter.bus; });

  const int per_page = RowsPerPage(settings, static_cast<int>(bus_nodes.size() + view.scenarios().size()));
  const int pages = PageCount(rows.size(), per_page);
  const int page = std::clamp(settings.page, 0, pages - 1);
  std::size_t faulted = 0;
  for (const auto& [key, row] : view.nodes())
    faulted += IsFaulted(row, now) ? 1 : 0;

  const auto paint = [&](const char* code, const std::string& text) {
    return settings.color ? std::string(code) + text + kReset : text;
  };

  std::string out;
  // The title: what matters most stays when the screen is narrow.
  std::vector<Part> title{
      {"canfleet top", 0, false, kBold},
      {FormatTime(now), 5},
      {Printf("%zu node%s on %zu bus%s, %zu faulted", view.nodes().size(),
              view.nodes().size() == 1 ? "" : "s", bus_nodes.size(), bus_nodes.size() == 1 ? "" : "es",
              faulted),
       1, false, faulted > 0 ? kRedBold : ""},
      {rows.size() != view.nodes().size() ? Printf("%zu shown", rows.size()) : std::string(), 2},
      {Printf("page %d/%d", page + 1, pages), pages > 1 ? 2 : 6},
      {std::string("sort ") + ToString(settings.sort) + (settings.reverse ? " (reversed)" : ""), 7},
  };
  std::string filter_text;
  if (!settings.filter.bus.empty()) filter_text += " bus=" + settings.filter.bus;
  if (!settings.filter.state.empty()) filter_text += " state=" + settings.filter.state;
  if (!settings.filter.text.empty()) filter_text += " text=" + settings.filter.text;
  if (!filter_text.empty()) title.push_back({"filter" + filter_text, 3, true});
  out += JoinParts(FitParts(title, width), settings.color) + "\n";

  for (const auto& [name, count] : bus_nodes) {
    const auto it = view.buses().find(name);
    const BusRow empty;
    const BusRow& bus = it == view.buses().end() ? empty : it->second;
    out += JoinParts(FitParts(BusParts(name, bus, count), width), settings.color) + "\n";
  }
  for (const auto& [source, scenario] : view.scenarios())
    out += JoinParts(FitParts(ScenarioParts(scenario, now), width), settings.color) + "\n";
  out += "\n";

  const Layout layout = ChooseColumns(rows, now, width);
  out += paint(kBold, HeaderLine(layout)) + "\n";

  const std::size_t first = static_cast<std::size_t>(page) * static_cast<std::size_t>(per_page);
  for (std::size_t i = first; i < rows.size() && i < first + static_cast<std::size_t>(per_page); ++i) {
    const NodeRow& row = *rows[i];
    const bool selected = settings.selected == row.status.key();
    // The selected row starts with "> ", with or without colors; in color it is in reverse video.
    std::string line = NodeLine(layout, row, now, selected);
    if (settings.color) {
      const bool changed = now - row.last_change < settings.highlight;
      const bool recent_emcy = row.last_emcy && now - row.last_emcy_time < settings.highlight;
      std::string prefix;
      switch (RowSeverity(row, now)) {
        case Severity::kFault:
          prefix += kRed;
          break;
        case Severity::kWarning:
          prefix += kYellow;
          break;
        case Severity::kNormal:
          break;
      }
      if (!row.alive) prefix += kDim;
      if (recent_emcy && !changed) prefix += kMagenta;
      if (recent_emcy || changed) prefix += kBold;  // fresh changes: bold (reverse is the selection)
      if (selected) {
        prefix += kReverse;
        line.resize(std::max<std::size_t>(line.size(), static_cast<std::size_t>(std::max(width, 0))), ' ');
      }
      if (!prefix.empty()) line = prefix + line + kReset;
    }
    out += line + "\n";
  }
  out += "\n";
  out += paint(kBold, "recent events") + "\n";
  const auto& recent = view.recent();
  std::vector<const FleetEvent*> shown;
  for (auto it = recent.rbegin();
       it != recent.rend() && static_cast<int>(shown.size()) < settings.event_lines; ++it) {
    if (it->kind == EventKind::kNodeSeen && it->from.empty()) continue;  // startup noise
    if (!settings.filter.bus.empty() && it->kind != EventKind::kVerdict && it->bus != settings.filter.bus)
      continue;
    shown.push_back(&*it);
  }
  for (int i = 0; i < settings.event_lines; ++i) {
    if (static_cast<std::size_t>(i) < shown.size()) {
      const FleetEvent& e = *shown[static_cast<std::size_t>(i)];
      const std::string text = FitLine(FormatEventText(e, true), width);
      const bool failed =
          e.kind == EventKind::kVerdict && e.verdict && e.verdict->result != telemetry::VerdictResult::kPass;
      const bool bad =
          e.kind == EventKind::kEmcy || e.kind == EventKind::kFault || e.kind == EventKind::kNodeGone;
      if (failed)
        out += paint(kRedBold, text);
      else if (e.kind == EventKind::kVerdict)
        out += paint(kGreen, text);
      else
        out += bad ? paint(kMagenta, text) : text;
    }
    out += "\n";
  }
  const std::string help =
      settings.filter_prompt.empty()
          ? "q quit  up/down select  Enter detail  n/p page  s sort  r reverse  / filter  "
            "f faults  a all  b bus  c clear"
          : "filter: " + settings.filter_prompt + "_";
  out += paint(kDim, FitLine(help, width)) + "\n";
  return out;
}

}  // namespace canfleet::tools
