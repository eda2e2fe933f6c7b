#include "bus/capture/candump_log.hpp"

#include "bus/text_append.hpp"

#include <cstdint>

#include "bus/capture/socketcan_layout.hpp"

namespace canfleet::capture {
namespace {

constexpr const char* kHex = kHexDigits;

}  // namespace

void AppendCandumpLogLine(std::string& out, const CanFrame& frame, WallTime time,
                          std::string_view interface) {
  const auto us = std::chrono::floor<std::chrono::microseconds>(time.time_since_epoch()).count();
  const std::uint64_t total_us = us < 0 ? 0 : static_cast<std::uint64_t>(us);
  out += '(';
  AppendDecimal(out, total_us / 1'000'000, 10);
  out += '.';
  AppendDecimal(out, total_us % 1'000'000, 6);
  out += ") ";
  out += interface;
  out += ' ';

  const SocketCanFrame f = ToSocketCan(frame);
  if ((f.can_id & kCanErrFlag) != 0) {
    AppendHex(out, f.can_id & (kCanErrMask | kCanErrFlag), 8);
  } else if ((f.can_id & kCanEffFlag) != 0) {
    AppendHex(out, f.can_id & kCanEffMask, 8);
  } else {
    AppendHex(out, f.can_id & kCanSffMask, 3);
  }
  out += '#';
  if ((f.can_id & kCanRtrFlag) != 0) {
    out += 'R';
    if (f.len != 0) out += kHex[f.len];  // can-utils prints a non-zero DLC of a remote frame
  } else {
    for (std::uint8_t i = 0; i < f.len; ++i)
      AppendHex(out, f.data[i], 2);
  }
  out += '\n';
}

std::string CandumpLogLine(const CanFrame& frame, WallTime time, std::string_view interface) {
  std::string out;
  AppendCandumpLogLine(out, frame, time, interface);
  return out;
}

CandumpLogWriter::CandumpLogWriter(const std::filesystem::path& path, std::string interface)
    : file_(path), interface_(std::move(interface)) {
  line_.reserve(64 + interface_.size());
}

void CandumpLogWriter::Write(const CanFrame& frame, WallTime time) {
  line_.clear();
  AppendCandumpLogLine(line_, frame, time, interface_);
  file_.Append(line_);
}

}  // namespace canfleet::capture
