#include "tools/telemetry/node_detail.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "tools/telemetry/event_format.hpp"
#include "tools/telemetry/text_fit.hpp"

namespace canfleet::tools {

namespace {

constexpr const char* kReset = "\x1b[0m";
constexpr const char* kBold = "\x1b[1m";
constexpr const char* kMagenta = "\x1b[35m";
constexpr const char* kDim = "\x1b[2m";

std::string Printf(const char* format, auto... args) {
  char text[512];
  std::snprintf(text, sizeof text, format, args...);
  return text;
}

/// Lines too long for the screen are cut at a word boundary and end in "...".
std::string Fit(const std::string& line, int width) {
  return FitLine(line, width);
}

std::string Consumers(const NodeStatusSample& s) {
  if (s.heartbeat_consumers.empty()) return "none";
  std::string text;
  for (const auto& c : s.heartbeat_consumers)
    text += Printf("%s#%u %s (%u ms, last %s)", text.empty() ? "" : ", ", c.node_id,
                   telemetry::ToString(c.state), c.time_ms, telemetry::StateName(c.last_state));
  return text;
}

/// "IN1.voltage_mV      1200 mV", "PS.state  on": the name in `name_width`, then the value with
/// its unit, or a bool's or an enum's word (IoValue.text: what `canfleet io get` prints).
std::string IoCell(const telemetry::IoValueSample& v, int name_width) {
  const std::string value =
      !v.text.empty() ? v.text : FormatIoValue(v.value) + (v.unit.empty() ? "" : " " + v.unit);
  return Printf("%-*.*s %12s", name_width, name_width, v.name.c_str(), value.c_str());
}

/// The longest name of `values`, at most `limit`.
int NameWidth(const std::vector<telemetry::IoValueSample>& values, int limit) {
  std::size_t longest = 1;
  for (const auto& v : values)
    longest = std::max(longest, v.name.size());
  return std::min(static_cast<int>(longest), std::max(1, limit));
}

}  // namespace

std::string FormatIoValue(double value) {
  if (!std::isfinite(value)) return Printf("%g", value);
  if (std::fabs(value - std::round(value)) < 1e-9 && std::fabs(value) < 1e15) return Printf("%.0f", value);
  std::string text = Printf("%.3f", value);
  while (text.back() == '0')
    text.pop_back();
  return text;
}

std::string RenderNodeDetail(const FleetView& view, const NodeKey& key, const RenderSettings& settings) {
  const WallTime now = settings.now;
  const int width = settings.width;
  const auto paint = [&](const char* code, const std::string& text) {
    return settings.color ? std::string(code) + text + kReset : text;
  };
  std::vector<std::string> top;     // status, I/O
  std::vector<std::string> bottom;  // 1003h hint, help
  const std::string help = "Esc back  up/down previous/next node  q quit";

  const auto it = view.nodes().find(key);
  const std::string who = key.bus + " #" + std::to_string(key.node_id);
  if (it == view.nodes().end()) {
    std::string out = paint(kBold, Fit("canfleet top  " + FormatTime(now) + "  " + who, width)) + "\n\n";
    out += Fit("no telemetry of " + who + " (gone before this monitor saw it)", width) + "\n\n";
    return out + paint(kDim, Fit(help, width)) + "\n";
  }
  const NodeRow& row = it->second;
  const NodeStatusSample& s = row.status;
  std::string state = row.alive ? telemetry::StateName(s.nmt_state) : (row.disposed ? "LEFT" : "LOST");
  const std::string who_named = s.name.empty() ? who : who + " " + s.name;
  if (IsStale(row, now)) state = "STALE";

  // The title keeps the node's name and address first; the time goes when the screen is narrow.
  top.push_back(JoinParts(FitParts({{"canfleet top", 0, false, kBold},
                                    {who_named, 0, false, kBold},
                                    {s.device, 1},
                                    {"(node detail)", 3},
                                    {FormatTime(now), 2}},
                                   width),
                          settings.color));
  top.push_back(Fit(Printf("NMT %s  controller %s  TEC %u  REC %u", state.c_str(),
                           telemetry::StateName(s.controller_state), s.tec, s.rec),
                    width));
  top.push_back(Fit(Printf("error register (1001h) %02Xh  uptime %s  status %s old", s.error_register,
                           FormatUptime(s.uptime).c_str(), FormatAge(now - row.last_sample).c_str()),
                    width));
  top.push_back(Fit(Printf("heartbeat produced every %u ms (1017h)", s.heartbeat_producer_ms), width));
  top.push_back(Fit("heartbeat consumed (1016h): " + Consumers(s), width));
  top.push_back(Fit(
      Printf("PDOs since the node process started: %llu received, %llu sent",
             static_cast<unsigned long long>(s.rpdo_count), static_cast<unsigned long long>(s.tpdo_count)),
      width));
  top.push_back("");

  // Simulated I/O: inputs and outputs side by side.
  if (!row.io) {
    top.push_back(Fit("simulated I/O: none published (a generic node has none)", width));
  } else {
    const auto& io = *row.io;
    // The outputs start 4 columns after the longest input cell, at most at half the width.
    const int half = std::max(20, width / 2);
    const int in_width = NameWidth(io.inputs, half - 17);
    const int out_width = NameWidth(io.outputs, half - 17);
    const int column = std::min(half, std::max(24, in_width + 13 + 4));
    top.push_back(
        paint(kBold, Fit(Printf("%-*s%s", column, Printf("SIMULATED INPUTS (%zu)", io.inputs.size()).c_str(),
                                Printf("SIMULATED OUTPUTS (%zu)", io.outputs.size()).c_str()),
                         width)));
    const std::size_t lines = std::max(io.inputs.size(), io.outputs.size());
    for (std::size_t i = 0; i < lines; ++i) {
      std::string line = i < io.inputs.size() ? IoCell(io.inputs[i], in_width) : std::string();
      line.resize(static_cast<std::size_t>(column), ' ');
      if (i < io.outputs.size()) line += IoCell(io.outputs[i], out_width);
      while (!line.empty() && line.back() == ' ')
        line.pop_back();
      top.push_back(Fit(line, width));
    }
  }
  top.push_back("");

  bottom.push_back(
      Fit("1003h (error history) is not telemetry: canfleet sdo read NODE 0x1003 1 u32 (sub 0: how many)",
          width));
  bottom.push_back(paint(kDim, Fit(help, width)));

  // The EMCY history fills what is left; the I/O gives way first to a screen too short for both.
  std::vector<std::string> emcy;
  emcy.push_back(
      paint(kBold, Fit(Printf("EMCYs FROM %s AS THE BUS SAW THEM (Emcy telemetry, newest first; %zu kept)",
                              who.c_str(), row.emcy_history.size()),
                       width)));
  emcy.push_back(Fit(Printf("%-24s %-6s %-4s %-15s %s", "TIME", "CODE", "REG", "DATA", "MEANING"), width));
  if (row.emcy_history.empty()) emcy.push_back(Fit("(none since the Emcy topic's history began)", width));
  std::vector<std::string> entries;
  for (auto e = row.emcy_history.rbegin(); e != row.emcy_history.rend(); ++e) {
    const auto& m = e->sample.emcy;
    std::string line = Fit(
        Printf("%-24s %04Xh  %02Xh  %02X %02X %02X %02X %02X  %s", FormatTime(e->time).c_str(), m.code,
               m.error_register, m.manufacturer[0], m.manufacturer[1], m.manufacturer[2], m.manufacturer[3],
               m.manufacturer[4], m.code == 0 ? "error reset or no error" : DescribeEmcyCode(m.code)),
        width);
    entries.push_back(now - e->time < settings.highlight ? paint(kMagenta, line) : line);
  }
  const int height = std::max(settings.height, 8);
  const int fixed = static_cast<int>(bottom.size() + emcy.size());
  int room = height - fixed;
  // At least the header and 3 entries of the EMCY history stay on screen.
  const int emcy_min = std::min<int>(3, static_cast<int>(entries.size()));
  if (static_cast<int>(top.size()) > room - emcy_min) {
    const int keep = std::max(1, room - emcy_min - 1);
    const std::size_t cut = top.size() - static_cast<std::size_t>(keep);
    top.resize(static_cast<std::size_t>(keep));
    top.push_back(Fit(Printf("... %zu more lines (a taller terminal shows them)", cut), width));
  }
  room -= static_cast<int>(top.size());
  if (static_cast<int>(entries.size()) > room) entries.resize(static_cast<std::size_t>(std::max(0, room)));

  std::string out;
  for (const auto& line : top)
    out += line + "\n";
  for (const auto& line : emcy)
    out += line + "\n";
  for (const auto& line : entries)
    out += line + "\n";
  for (const auto& line : bottom)
    out += line + "\n";
  return out;
}

}  // namespace canfleet::tools
