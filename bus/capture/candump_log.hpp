#pragma once
/// @file The candump log format: what `candump -l` writes and `canplayer` / `log2asc` read.
///
///     (1700000000.123456) can0 123#DEADBEEF
///     (1700000000.123789) can0 1ABCDEF0#0011223344556677     extended: 8 hex digits
///     (1700000000.124000) can0 705#R1                       remote frame, DLC 1 (none if 0)
///     (1700000000.125000) can0 20000088#0000000000000000     error frame: CAN_ERR_FLAG | class
///
/// One frame per line: the time as seconds (10 digits, zero-padded) and microseconds (6 digits),
/// the interface name, then can-utils' compact frame notation with upper-case hex (lib.c
/// snprintf_canframe: 3 digits for an 11-bit id, 8 for a 29-bit id or an error frame).

#include <filesystem>
#include <string>
#include <string_view>

#include "bus/capture/capture_file.hpp"
#include "bus/capture/capture_writer.hpp"

namespace canfleet::capture {

/// Appends one log line (with its '\n') to `out`. Times before the epoch are written as 0.
void AppendCandumpLogLine(std::string& out, const CanFrame& frame, WallTime time, std::string_view interface);
std::string CandumpLogLine(const CanFrame& frame, WallTime time, std::string_view interface);

class CandumpLogWriter final : public CaptureWriter {
 public:
  /// `interface` is the name written on each line (the bus name, e.g. "can0"); canplayer maps it
  /// to a real interface with `canplayer vcan0=can0 -I file`. Throws std::system_error when the
  /// file cannot be created.
  CandumpLogWriter(const std::filesystem::path& path, std::string interface);

  void Write(const CanFrame& frame, WallTime time) override;
  void Flush() override { file_.Flush(); }
  void Close() override { file_.Close(); }
  bool ok() const override { return file_.ok(); }
  const std::string& error() const override { return file_.error(); }

 private:
  CaptureFile file_;
  std::string interface_;
  std::string line_;  ///< reused for each line: no allocation per frame
};

}  // namespace canfleet::capture
