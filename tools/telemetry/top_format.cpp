#include "tools/telemetry/top_format.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <tuple>

#include "tools/telemetry/event_format.hpp"
#include "tools/telemetry/node_detail.hpp"

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
  }
  return "?";
}

std::optional<SortKey> ParseSortKey(std::string_view text) {
  for (auto key :
       {SortKey::kBusNode, SortKey::kState, SortKey::kErrors, SortKey::kLastChange, SortKey::kDevice}) {
    if (text == ToString(key)) return key;
  }
  return std::nullopt;
}

SortKey NextSortKey(SortKey key) {
  switch (key) {
    case SortKey::kBusNode:
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
constexpr const char* kYellow = "\x1b[33m";
constexpr const char* kMagenta = "\x1b[35m";
constexpr const char* kDim = "\x1b[2m";
constexpr const char* kUnderline = "\x1b[4m";

std::string Printf(const char* format, auto... args) {
  char text[512];
  std::snprintf(text, sizeof text, format, args...);
  return text;
}

/// Cuts a line to `width` visible characters (our lines are ASCII apart from escapes, added after).
std::string Fit(std::string line, int width) {
  if (width > 0 && line.size() > static_cast<std::size_t>(width))
    line.resize(static_cast<std::size_t>(width));
  return line;
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

std::string NodeLine(const NodeRow& row, WallTime now) {
  const auto& s = row.status;
  std::string nmt = row.alive ? telemetry::ShortName(s.nmt_state) : (row.disposed ? "LEFT" : "LOST");
  if (IsStale(row, now)) nmt = "STALE";
  std::string emcy = "-";
  if (s.last_emcy) {
    emcy = Printf("%04Xh %02Xh", s.last_emcy->code, s.last_emcy->error_register);
    if (row.last_emcy) emcy += " " + FormatAge(now - row.last_emcy_time);
  }
  return Printf("%-8.8s %3u  %-18.18s %-6s %-8s %4u %3u  %02Xh %6u %-7s %9llu %9llu %9s  %-19.19s %6s",
                s.bus.c_str(), s.node_id, s.device.c_str(), nmt.c_str(),
                telemetry::ShortName(s.controller_state), s.tec, s.rec, s.error_register,
                s.heartbeat_producer_ms, Consumers(row).c_str(),
                static_cast<unsigned long long>(s.rpdo_count), static_cast<unsigned long long>(s.tpdo_count),
                FormatUptime(s.uptime).c_str(), emcy.c_str(), FormatAge(now - row.last_sample).c_str());
}

std::string BusLine(const std::string& name, const BusRow& bus, int node_count) {
  std::string line = Printf("%-8.8s", name.c_str());
  if (bus.stats) {
    const auto& s = *bus.stats;
    line +=
        Printf(" %5u kbit/s %-9.9s load %5.1f%%  %7.0f fr/s  err %llu  ports %u", s.bitrate / 1000,
               s.mode.c_str(), static_cast<double>(s.load_percent), static_cast<double>(s.frames_per_second),
               static_cast<unsigned long long>(s.error_frames), s.node_count);
    if (s.mode == "virtual")
      line += Printf("  t=%.1f s (%.0fx)", s.simulated_s, static_cast<double>(s.speed_factor));
    if (!s.top_cob_ids.empty()) {
      line += "  top";
      for (std::size_t i = 0; i < s.top_cob_ids.size() && i < 4; ++i) {
        line += Printf(" %03Xh:%.0f", s.top_cob_ids[i].cob_id,
                       static_cast<double>(s.top_cob_ids[i].frames_per_second));
      }
    }
  } else {
    line += " (no bus statistics)";
  }
  line += Printf("  nodes %d", node_count);
  return line;
}

std::string FaultList(const BusRow& bus) {
  std::string text;
  for (const auto& [id, fault] : bus.active_faults) {
    text += Printf(" #%u %s", id, fault.kind.c_str());
    if (fault.target_node != 0) text += Printf(" node %u", fault.target_node);
  }
  return text;
}

}  // namespace

bool IsValidStateFilter(std::string_view state) {
  static constexpr std::array<std::string_view, 9> kWords{"oper",    "preop",   "stop",  "init", "active",
                                                          "passive", "bus-off", "fault", "ok"};
  const std::string lower = Lower(state);
  return state.empty() || std::find(kWords.begin(), kWords.end(), lower) != kWords.end();
}

bool Matches(const NodeRow& row, const TopFilter& filter, WallTime now) {
  const auto& s = row.status;
  if (!filter.bus.empty() && s.bus != filter.bus) return false;
  if (!filter.state.empty()) {
    const std::string state = Lower(filter.state);
    if (state == "fault") {
      if (!IsFaulted(row, now)) return false;
    } else if (state == "ok") {
      if (IsFaulted(row, now)) return false;
    } else if (state == "active" || state == "passive" || state == "bus-off") {
      if (state != telemetry::ShortName(s.controller_state)) return false;
    } else if (state != Lower(telemetry::ShortName(s.nmt_state))) {
      return false;
    }
  }
  if (!filter.text.empty()) {
    const std::string haystack = Lower(s.bus + " #" + std::to_string(s.node_id) + " " + s.device);
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
  }
  if (reverse) std::reverse(rows.begin(), rows.end());
  return rows;
}

int RowsPerPage(const RenderSettings& settings, int bus_count) {
  // title + bus lines + blank + column header ... + blank + "events" + event lines + help line
  const int fixed = 1 + bus_count + 1 + 1 + 1 + 1 + settings.event_lines + 1;
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

std::string RenderFrame(const FleetView& view, const RenderSettings& settings) {
  if (settings.detail && settings.selected) return RenderNodeDetail(view, *settings.selected, settings);
  const WallTime now = settings.now;
  const auto rows = SelectRows(view, settings.filter, settings.sort, settings.reverse, now);

  // Buses: every bus that has statistics or nodes, unless filtered to one.
  std::map<std::string, int> bus_nodes;
  for (const auto& [name, bus] : view.buses())
    bus_nodes[name];
  for (const auto& [key, row] : view.nodes())
    ++bus_nodes[key.bus];
  if (!settings.filter.bus.empty())
    std::erase_if(bus_nodes, [&](const auto& b) { return b.first != settings.filter.bus; });

  const int per_page = RowsPerPage(settings, static_cast<int>(bus_nodes.size()));
  const int pages = PageCount(rows.size(), per_page);
  const int page = std::clamp(settings.page, 0, pages - 1);
  std::size_t faulted = 0;
  for (const auto& [key, row] : view.nodes())
    faulted += IsFaulted(row, now) ? 1 : 0;

  const auto paint = [&](const char* code, const std::string& text) {
    return settings.color ? std::string(code) + text + kReset : text;
  };

  std::string out;
  std::string title =
      Printf("canfleet top  %s  %zu nodes on %zu buses, %zu faulted, %zu shown  page %d/%d  sort %s%s",
             FormatTime(now).c_str(), view.nodes().size(), bus_nodes.size(), faulted, rows.size(), page + 1,
             pages, ToString(settings.sort), settings.reverse ? " (reversed)" : "");
  std::string filter_text;
  if (!settings.filter.bus.empty()) filter_text += " bus=" + settings.filter.bus;
  if (!settings.filter.state.empty()) filter_text += " state=" + settings.filter.state;
  if (!settings.filter.text.empty()) filter_text += " text=" + settings.filter.text;
  if (!filter_text.empty()) title += "  filter" + filter_text;
  out += paint(kBold, Fit(title, settings.width)) + "\n";

  for (const auto& [name, count] : bus_nodes) {
    const auto it = view.buses().find(name);
    const BusRow empty;
    const BusRow& bus = it == view.buses().end() ? empty : it->second;
    const std::string line = BusLine(name, bus, count);
    const std::string faults = FaultList(bus);
    std::string fitted = Fit(faults.empty() ? line : line + "  FAULTS" + faults, settings.width);
    if (settings.color && fitted.size() > line.size()) {
      fitted = fitted.substr(0, line.size()) + kRed + kBold + fitted.substr(line.size()) + kReset;
    }
    out += fitted + "\n";
  }
  out += "\n";
  out += paint(kBold, Fit(Printf("%-8s %3s  %-18s %-6s %-8s %4s %3s  %3s %6s %-7s %9s %9s %9s  %-19s %6s",
                                 "BUS", "ID", "DEVICE", "NMT", "CTRL", "TEC", "REC", "ERR", "HB ms", "CONS",
                                 "RPDO", "TPDO", "UPTIME", "LAST EMCY", "AGE"),
                          settings.width)) +
         "\n";

  const std::size_t first = static_cast<std::size_t>(page) * static_cast<std::size_t>(per_page);
  for (std::size_t i = first; i < rows.size() && i < first + static_cast<std::size_t>(per_page); ++i) {
    const NodeRow& row = *rows[i];
    const bool selected = settings.selected == row.status.key();
    // The selected row ends in "<" (plain) or is underlined (color); its start stays the bus name.
    std::string line =
        Fit(NodeLine(row, now), selected && !settings.color ? settings.width - 2 : settings.width);
    if (selected && !settings.color) line += " <";
    if (selected && settings.color) line = kUnderline + line + kReset;
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
      if (changed) prefix += kReverse;
      if (recent_emcy && !changed) prefix += kMagenta;
      if (recent_emcy || changed) prefix += kBold;
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
    if (!settings.filter.bus.empty() && it->bus != settings.filter.bus) continue;
    shown.push_back(&*it);
  }
  for (int i = 0; i < settings.event_lines; ++i) {
    if (static_cast<std::size_t>(i) < shown.size()) {
      const FleetEvent& e = *shown[static_cast<std::size_t>(i)];
      const bool bad =
          e.kind == EventKind::kEmcy || e.kind == EventKind::kFault || e.kind == EventKind::kNodeGone;
      out += (bad ? paint(kMagenta, Fit(FormatEventText(e), settings.width))
                  : Fit(FormatEventText(e), settings.width));
    }
    out += "\n";
  }
  const std::string help = settings.filter_prompt.empty()
                               ? "q quit  up/down select  Enter node detail  n/p page  s sort  r reverse  / "
                                 "filter  f faults only  "
                                 "a all  b bus  c clear"
                               : "filter: " + settings.filter_prompt + "_";
  out += paint(kDim, Fit(help, settings.width)) + "\n";
  return out;
}

}  // namespace canfleet::tools
