#include "orchestrator/socketcand/protocol.hpp"

#include "bus/text_append.hpp"

#include <array>
#include <optional>

namespace canfleet::socketcand {
namespace {

constexpr const char* kHex = kHexDigits;

bool IsSpace(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

int HexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

std::optional<std::uint32_t> ParseHex(std::string_view text, std::size_t max_digits) {
  if (text.empty() || text.size() > max_digits) return std::nullopt;
  std::uint32_t value = 0;
  for (char c : text) {
    const int v = HexValue(c);
    if (v < 0) return std::nullopt;
    value = (value << 4) | static_cast<std::uint32_t>(v);
  }
  return value;
}

/// The fields between '<' and '>', split on whitespace. At most kMaxFields are kept; `count` says
/// how many there were.
struct Fields {
  static constexpr std::size_t kMaxFields = 12;  // "send ID DLC" + 8 bytes + 1 to detect excess
  std::array<std::string_view, kMaxFields> field{};
  std::size_t count = 0;
};

Fields Split(std::string_view inner) {
  Fields f;
  std::size_t i = 0;
  while (i < inner.size()) {
    while (i < inner.size() && IsSpace(inner[i]))
      ++i;
    if (i == inner.size()) break;
    const std::size_t start = i;
    while (i < inner.size() && !IsSpace(inner[i]))
      ++i;
    if (f.count < Fields::kMaxFields) f.field[f.count] = inner.substr(start, i - start);
    ++f.count;
  }
  return f;
}

Command Malformed(const char* why) {
  Command c;
  c.kind = CommandKind::kMalformed;
  c.error = why;
  return c;
}

/// "ID DLC [bytes]" (send) or "ID DLC" (sendrtr), starting at field 1.
Command ParseFrame(const Fields& f, bool remote) {
  if (f.count < 3) return Malformed("expected an identifier and a DLC");
  const std::string_view id_text = f.field[1];
  const auto id = ParseHex(id_text, 8);
  if (!id) return Malformed("identifier is not 1..8 hex digits");
  if (*id > CanFrame::kMaxExtendedId) return Malformed("identifier above 1FFFFFFF");
  const std::string_view dlc_text = f.field[2];
  if (dlc_text.size() != 1 || dlc_text[0] < '0' || dlc_text[0] > '8') return Malformed("DLC is not 0..8");
  const auto dlc = static_cast<std::uint8_t>(dlc_text[0] - '0');

  CanFrame frame;
  frame.id = *id;
  frame.dlc = dlc;
  if (id_text.size() == 8 || *id > CanFrame::kMaxStandardId) frame.flags |= CanFrame::kExtended;
  if (remote) {
    if (f.count != 3) return Malformed("sendrtr takes no data bytes");
    frame.flags |= CanFrame::kRemote;
  } else {
    if (f.count != 3u + dlc) return Malformed("number of data bytes differs from the DLC");
    for (std::uint8_t i = 0; i < dlc; ++i) {
      const auto byte = ParseHex(f.field[3 + i], 2);
      if (!byte) return Malformed("data byte is not 1..2 hex digits");
      frame.data[i] = static_cast<std::uint8_t>(*byte);
    }
  }
  Command c;
  c.kind = remote ? CommandKind::kSendRtr : CommandKind::kSend;
  c.frame = frame;
  return c;
}

void AppendId(std::string& out, const CanFrame& frame) {
  if (frame.extended()) {
    AppendHex(out, frame.id & CanFrame::kMaxExtendedId, 8);
  } else {
    AppendHex(out, frame.id & CanFrame::kMaxStandardId, 3);
  }
}

void AppendTime(std::string& out, WallTime time) {
  const auto us = std::chrono::floor<std::chrono::microseconds>(time.time_since_epoch()).count();
  const std::uint64_t total_us = us < 0 ? 0 : static_cast<std::uint64_t>(us);
  AppendDecimal(out, total_us / 1'000'000, 1);
  out += '.';
  AppendDecimal(out, total_us % 1'000'000, 6);
}

/// Inserts spaces at `start` so that out[start..] fills a multiple of kAlignedRecordSize.
void PadFrom(std::string& out, std::size_t start) {
  const std::size_t length = out.size() - start;
  const std::size_t padded = (length + kAlignedRecordSize - 1) / kAlignedRecordSize * kAlignedRecordSize;
  out.insert(start, padded - length, ' ');
}

}  // namespace

void ElementReader::Feed(std::string_view bytes) {
  if (pos_ > 0) {
    buffer_.erase(0, pos_);
    pos_ = 0;
  }
  buffer_.append(bytes);
}

ElementReader::Result ElementReader::Next() {
  for (;;) {
    const std::size_t open = buffer_.find('<', pos_);
    if (open == std::string::npos) {
      discarded_ += buffer_.size() - pos_;
      buffer_.clear();
      pos_ = 0;
      return {};
    }
    discarded_ += open - pos_;
    pos_ = open;
    const std::size_t close = buffer_.find_first_of("<>", open + 1);
    if (close == std::string::npos) {
      if (buffer_.size() - open > kMaxElementLength) return {Status::kTooLong, {}};
      return {};
    }
    if (buffer_[close] == '<') {  // an unterminated element followed by a new one: drop it
      discarded_ += close - open;
      pos_ = close;
      continue;
    }
    if (close + 1 - open > kMaxElementLength) return {Status::kTooLong, {}};
    pos_ = close + 1;
    return {Status::kElement, std::string_view(buffer_).substr(open, close + 1 - open)};
  }
}

namespace {

Command ParseFields(const Fields& f) {
  const std::string_view word = f.field[0];
  Command c;
  c.argument = word;
  auto single = [&](CommandKind kind) {
    if (f.count != 1) return Malformed("command takes no arguments");
    c.kind = kind;
    return c;
  };
  if (word == "open") {
    if (f.count != 2) return Malformed("open takes one bus name");
    if (f.field[1].size() > kMaxBusNameLength) return Malformed("bus name longer than 16 characters");
    c.kind = CommandKind::kOpen;
    c.argument = f.field[1];
    return c;
  }
  if (word == "rawmode") return single(CommandKind::kRawMode);
  if (word == "bcmmode") return single(CommandKind::kBcmMode);
  if (word == "isotpmode") return single(CommandKind::kIsotpMode);
  if (word == "controlmode") return single(CommandKind::kControlMode);
  if (word == "echo") return single(CommandKind::kEcho);
  if (word == "send") return ParseFrame(f, false);
  if (word == "sendrtr") return ParseFrame(f, true);
  for (std::string_view bcm :
       {"add", "update", "delete", "filter", "muxfilter", "subscribe", "unsubscribe"}) {
    if (word == bcm) {
      c.kind = CommandKind::kBcmCommand;
      return c;
    }
  }
  // "< can0 B ... >" / "< can0 C ... >": bus configuration in NO_BUS mode (state_nobus.c).
  if (f.count >= 2 && (f.field[1] == "B" || f.field[1] == "C")) {
    c.kind = CommandKind::kBusConfig;
    return c;
  }
  c.kind = CommandKind::kUnknown;
  return c;
}

}  // namespace

Command ParseCommand(std::string_view element) {
  if (element.size() < 2 || element.front() != '<' || element.back() != '>')
    return Malformed("not an element < ... >");
  const Fields f = Split(element.substr(1, element.size() - 2));
  if (f.count == 0) return Malformed("empty element");
  Command c = ParseFields(f);
  if (c.kind != CommandKind::kOpen) c.argument = f.field[0];
  return c;
}

bool AppendFrame(std::string& out, const CanFrame& frame, WallTime time, bool aligned) {
  if (frame.error()) return false;
  const std::size_t start = out.size();
  if (frame.remote()) {
    out += "< rtr ";
    AppendId(out, frame);
    out += ' ';
    AppendTime(out, time);
    out += ' ';
    out += kHex[frame.dlc <= 8 ? frame.dlc : 8];
    out += " >";
  } else {
    out += "< frame ";
    AppendId(out, frame);
    out += ' ';
    AppendTime(out, time);
    out += ' ';
    for (std::uint8_t i = 0; i < frame.dlc && i < 8; ++i)
      AppendHex(out, frame.data[i], 2);
    out += " >";
  }
  if (aligned) PadFrom(out, start);
  return true;
}

void AppendMessage(std::string& out, std::string_view message, bool aligned) {
  const std::size_t start = out.size();
  out += message;
  if (aligned) PadFrom(out, start);
}

std::string FormatSend(const CanFrame& frame) {
  std::string out = frame.remote() ? "< sendrtr " : "< send ";
  AppendId(out, frame);
  out += ' ';
  out += kHex[frame.dlc <= 8 ? frame.dlc : 8];
  if (!frame.remote()) {
    for (std::uint8_t i = 0; i < frame.dlc && i < 8; ++i) {
      out += ' ';
      AppendHex(out, frame.data[i], 2);
    }
  }
  out += " >";
  return out;
}

}  // namespace canfleet::socketcand
