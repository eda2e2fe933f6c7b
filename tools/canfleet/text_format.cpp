#include "tools/canfleet/text_format.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "bus/capture/candump_log.hpp"
#include "orchestrator/control/sdo_value.hpp"

namespace canfleet::cli {

namespace {

std::string Printf(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, value);
  return buffer;
}

template <class Repeated>
std::string Join(const Repeated& items, const char* separator = ",") {
  std::string out;
  for (const auto& item : items) {
    if (!out.empty()) out += separator;
    if constexpr (std::is_arithmetic_v<std::decay_t<decltype(item)>>)
      out += std::to_string(item);
    else
      out += item;
  }
  return out;
}

std::string Hex4(std::uint32_t value) {
  char buffer[16];
  std::snprintf(buffer, sizeof buffer, "%04X", value);
  return buffer;
}

std::string Hex2(std::uint32_t value) {
  char buffer[16];
  std::snprintf(buffer, sizeof buffer, "%02X", value);
  return buffer;
}

std::string Process(const control::NodeStatus& node) {
  std::string text = node.process();
  if (node.process() == "external") text += node.attached() ? " (attached)" : " (not attached)";
  if (!node.detail().empty()) text += " (" + node.detail() + ")";
  if (node.restarts() != 0)
    text += ", " + std::to_string(node.restarts()) + (node.restarts() == 1 ? " restart" : " restarts");
  return text;
}

/// The CONTROLLER column: the state, and the port's bit rate when it is not its bus's
/// ("error-passive @250k": a node at the wrong rate sees no traffic).
/// The NMT state, marked when it is old news (no heartbeat for three of the node's periods).
std::string NmtText(const std::string& state, bool stale) {
  if (state.empty()) return "-";
  return stale ? state + " (stale)" : state;
}

std::string ControllerText(const control::PortStatus& port) {
  std::string text = port.controller().empty() ? "-" : port.controller();
  if (port.bitrate() != 0) text += " @" + FormatBitrate(port.bitrate());
  return text;
}

/// `node` is a NodeStatus or a PortStatus.
template <class Node>
std::string LastEmcy(const Node& node) {
  if (!node.has_last_emcy()) return "-";
  const control::Emcy& e = node.last_emcy();
  std::string text = Hex4(e.code()) + "h reg " + Hex2(e.register_()) + "h at " + FormatSeconds(e.time_s());
  if (node.emcy_count() > 1) text += " (" + std::to_string(node.emcy_count()) + " total)";
  return text;
}

}  // namespace

Table::Table(std::vector<std::string> headers)
    : headers_(std::move(headers)), right_(headers_.size(), false) {}

void Table::AddRow(std::vector<std::string> cells) {
  cells.resize(headers_.size());
  rows_.push_back(std::move(cells));
}

void Table::AlignRight(std::size_t column) {
  if (column < right_.size()) right_[column] = true;
}

std::string Table::Render() const {
  std::vector<std::size_t> width(headers_.size());
  for (std::size_t c = 0; c < headers_.size(); ++c) {
    width[c] = headers_[c].size();
    for (const auto& row : rows_)
      width[c] = std::max(width[c], row[c].size());
  }
  std::string out;
  auto line = [&](const std::vector<std::string>& cells) {
    std::string text;
    for (std::size_t c = 0; c < cells.size(); ++c) {
      const std::size_t pad = width[c] - cells[c].size();
      if (c != 0) text += "  ";
      if (right_[c]) text.append(pad, ' ');
      text += cells[c];
      if (!right_[c] && c + 1 != cells.size()) text.append(pad, ' ');
    }
    while (!text.empty() && text.back() == ' ')
      text.pop_back();
    out += text + '\n';
  };
  line(headers_);
  for (const auto& row : rows_)
    line(row);
  return out;
}

std::string FormatSeconds(double seconds) {
  if (seconds < 0) return "-";
  return Printf("%.1f", seconds) + "s";
}

std::string FormatUptime(double seconds) {
  const auto total = static_cast<long long>(std::max(0.0, std::floor(seconds)));
  const long long h = total / 3600;
  const long long m = total / 60 % 60;
  const long long s = total % 60;
  char buffer[64];
  if (h != 0)
    std::snprintf(buffer, sizeof buffer, "%lldh%02lldm%02llds", h, m, s);
  else if (m != 0)
    std::snprintf(buffer, sizeof buffer, "%lldm%02llds", m, s);
  else
    std::snprintf(buffer, sizeof buffer, "%llds", s);
  return buffer;
}

std::string FormatBitrate(std::uint32_t bitrate) {
  if (bitrate != 0 && bitrate % 1'000'000 == 0) return std::to_string(bitrate / 1'000'000) + "M";
  if (bitrate != 0 && bitrate % 1'000 == 0) return std::to_string(bitrate / 1'000) + "k";
  return std::to_string(bitrate);
}

std::string FormatRate(double value) {
  return Printf("%.1f", value);
}

std::string FormatStatus(const control::Status& status) {
  std::string out = "topology " + (status.topology().empty() ? std::string("?") : status.topology()) +
                    ", up " + FormatUptime(status.uptime_s());
  if (status.virtual_time()) {
    char factor[96];
    std::snprintf(factor, sizeof factor, " (virtual time, %.1fx real time%s)", status.speed_factor(),
                  status.speed() > 0
                      ? (", paced at " + std::to_string(static_cast<int>(status.speed())) + "x").c_str()
                      : ", as fast as possible");
    out += factor;
  }
  out += "\n\n";

  Table buses({"BUS", "BITRATE", "LOAD", "FRAMES/S", "ERRORS/S", "FRAMES", "ERRORS", "PORTS"});
  for (std::size_t c = 1; c < 8; ++c)
    buses.AlignRight(c);
  for (const auto& b : status.buses())
    buses.AddRow({b.name(), FormatBitrate(b.bitrate()) + (b.paced() ? "" : " (unpaced)"),
                  Printf("%.1f", b.load_percent()) + "%", FormatRate(b.frames_per_s()),
                  FormatRate(b.error_frames_per_s()), std::to_string(b.frames()),
                  std::to_string(b.error_frames()), std::to_string(b.ports())});
  out += buses.Render() + "\n";

  if (status.nodes().empty()) {
    out += "no nodes\n";
  } else {
    Table nodes({"NODE", "DEVICE", "ID", "BUS", "PROCESS", "PID", "NMT", "CONTROLLER", "TEC", "REC",
                 "HEARTBEAT", "LAST EMCY"});
    for (const std::size_t c : {2u, 5u, 8u, 9u, 10u})
      nodes.AlignRight(c);
    for (const auto& n : status.nodes()) {
      if (n.ports_size() > 1) {
        // One row per CAN port: each has its own node-ID, NMT state, controller and EMCYs.
        for (int p = 0; p < n.ports_size(); ++p) {
          const auto& port = n.ports(p);
          const bool first = p == 0;
          nodes.AddRow({first ? n.name() : "  CAN" + std::to_string(p + 1), first ? n.device() : "",
                        std::to_string(port.node_id()), port.bus(), first ? Process(n) : "",
                        first && n.pid() != 0 ? std::to_string(n.pid()) : (first ? "-" : ""),
                        NmtText(port.nmt_state(), port.nmt_stale()), ControllerText(port),
                        std::to_string(port.tec()), std::to_string(port.rec()),
                        FormatSeconds(port.heartbeat_age_s()), LastEmcy(port)});
        }
        continue;
      }
      nodes.AddRow(
          {n.name(), n.device(), Join(n.node_ids()), Join(n.buses()), Process(n),
           n.pid() != 0 ? std::to_string(n.pid()) : "-", NmtText(n.nmt_state(), n.nmt_stale()),
           n.ports_size() == 1 ? ControllerText(n.ports(0)) : (n.controller().empty() ? "-" : n.controller()),
           std::to_string(n.tec()), std::to_string(n.rec()), FormatSeconds(n.heartbeat_age_s()),
           LastEmcy(n)});
    }
    out += nodes.Render();
  }
  out += "\n";

  control::FaultList active;
  *active.mutable_faults() = status.faults();
  out += FormatFaultList(active, false);
  return out;
}

std::string FormatFaultList(const control::FaultList& list, bool include_ended) {
  if (list.faults().empty()) return include_ended ? "no faults\n" : "no active faults\n";
  Table table({"FAULT", "STATE", "STARTED", "ENDED", "HITS", "LABEL", "SUMMARY"});
  for (const std::size_t c : {0u, 2u, 3u, 4u})
    table.AlignRight(c);
  for (const auto& f : list.faults())
    table.AddRow({std::to_string(f.fault_id()), f.state(), FormatSeconds(f.started_s()),
                  f.ended_s() > 0 ? FormatSeconds(f.ended_s()) : "-", std::to_string(f.hits()),
                  f.spec().label().empty() ? "-" : f.spec().label(), f.summary()});
  return table.Render();
}

std::string FormatFaultInjected(const control::FaultInjected& injected) {
  return "fault " + std::to_string(injected.fault_id()) + ": " + injected.summary() + "\n";
}

std::string FormatIoValues(const control::IoValues& values) {
  if (values.values().empty()) return "no signals\n";
  Table table({"SIGNAL", "VALUE", "UNIT", "DIRECTION"});
  table.AlignRight(1);
  for (const auto& v : values.values())
    table.AddRow({v.name(), v.value(), v.unit().empty() ? "-" : v.unit(), v.input() ? "input" : "output"});
  return table.Render();
}

std::string FormatSdoData(const control::SdoData& data) {
  if (!data.text().empty()) return data.text() + "\n";
  const auto& bytes = data.data();
  return control::HexBytes(std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(bytes.data()),
                                                         bytes.size())) +
         "\n";
}

std::string FormatFrame(const control::Frame& frame) {
  CanFrame f;
  f.id = frame.id();
  f.flags = static_cast<std::uint8_t>((frame.extended() ? CanFrame::kExtended : 0) |
                                      (frame.remote() ? CanFrame::kRemote : 0) |
                                      (frame.error() ? CanFrame::kError : 0));
  // A remote frame's requested DLC travels as the length of its (zero) data.
  f.dlc = static_cast<std::uint8_t>(std::min<std::size_t>(frame.data().size(), 8));
  if (!frame.remote()) std::copy_n(frame.data().begin(), f.dlc, f.data.begin());
  return capture::CandumpLogLine(f, capture::WallTime(std::chrono::nanoseconds(frame.time_ns())),
                                 frame.bus());
}

std::string FormatCaptureStarted(const control::CaptureStarted& started, const std::string& bus) {
  return "capture " + std::to_string(started.capture_id()) + ": " + bus + " -> " + started.path() + "\n";
}

}  // namespace canfleet::cli
