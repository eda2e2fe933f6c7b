#pragma once
/// @file How `canfleet` shows responses to people: aligned tables and one-line summaries. Kept
/// apart from the commands so that every format is in one place.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "orchestrator/control/canfleet_control.pb.h"

namespace canfleet::cli {

/// A plain-text table: a header row, then rows, columns separated by two spaces and as wide as
/// their widest cell; no trailing spaces.
class Table {
 public:
  explicit Table(std::vector<std::string> headers);
  void AddRow(std::vector<std::string> cells);
  /// Numbers read better right-aligned.
  void AlignRight(std::size_t column);
  std::string Render() const;
  bool empty() const { return rows_.empty(); }

 private:
  std::vector<std::string> headers_;
  std::vector<std::vector<std::string>> rows_;
  std::vector<bool> right_;
};

/// "12.3s"; "-" for a negative time (none).
std::string FormatSeconds(double seconds);
/// "45s", "3m07s", "2h03m07s".
std::string FormatUptime(double seconds);
/// "250k", "1M", "83.333k", "33333" (bit/s).
std::string FormatBitrate(std::uint32_t bitrate);
/// "12.5" (one decimal).
std::string FormatRate(double value);

/// The whole `canfleet status` text: a title line, the buses, the nodes, the active faults.
std::string FormatStatus(const control::Status& status);
/// `canfleet fault list`: a table, or "no active faults" / "no faults".
std::string FormatFaultList(const control::FaultList& list, bool include_ended);
/// `canfleet fault inject`: "fault 3: heartbeat-loss of quad-5 on can0 (to all receivers), until cleared".
std::string FormatFaultInjected(const control::FaultInjected& injected);
/// `canfleet io get NODE`: a table of signals.
std::string FormatIoValues(const control::IoValues& values);
/// `canfleet sdo read`: the text the orchestrator formatted, else the bytes in hex.
std::string FormatSdoData(const control::SdoData& data);
/// `canfleet dump`: one candump log line, "(1700000000.123456) can0 185#0102030405060708\n".
std::string FormatFrame(const control::Frame& frame);
/// `canfleet capture start`: "capture 1: can0 -> /abs/file.pcap".
std::string FormatCaptureStarted(const control::CaptureStarted& started, const std::string& bus);

}  // namespace canfleet::cli
