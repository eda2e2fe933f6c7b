#include "node/canopen/eds/eds_value.hpp"

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>

#include "node/canopen/eds/eds_error.hpp"
#include "node/canopen/eds/eds_number.hpp"
#include "node/canopen/eds/ini_lexer.hpp"

namespace canfleet::canopen {
namespace {

constexpr std::string_view kNodeId = "$NODEID";

[[noreturn]] void Fail(std::string detail) {
  throw EdsValueError(std::move(detail));
}

std::string NotANumber(std::string_view text) {
  return QuoteForError(text) + " is not a number";
}

std::size_t FindNodeId(std::string_view text) {
  auto it = std::search(text.begin(), text.end(), kNodeId.begin(), kNodeId.end(), [](char a, char b) {
    return std::toupper(static_cast<unsigned char>(a)) == static_cast<unsigned char>(b);
  });
  return it == text.end() ? std::string_view::npos : static_cast<std::size_t>(it - text.begin());
}

std::string RangeText(DataType type, long double low, long double high) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "out of range for %s (%.0Lf..%.0Lf)", std::string(ToString(type)).c_str(),
                low, high);
  return buf;
}

/// Encodes an integer literal in the type's size, checking the type's range. A signed type also
/// takes a hex literal up to the full width as two's complement (0xFFFF = -1 for INTEGER16), as
/// vendor tools write limits that way.
Bytes EncodeInteger(DataType type, std::string_view text) {
  auto literal = ParseIntegerLiteral(text);
  if (!literal) Fail(NotANumber(text));
  const std::size_t size = *FixedSize(type);
  const unsigned bits = type == DataType::kBoolean ? 1u : static_cast<unsigned>(size * 8);
  const std::uint64_t full = bits == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << bits) - 1;
  if (!IsSigned(type)) {
    if ((literal->negative && literal->magnitude != 0) || literal->magnitude > full) {
      Fail(QuoteForError(text) + " is " + RangeText(type, 0, static_cast<long double>(full)));
    }
    return EncodeLe(literal->magnitude, size);
  }
  const std::uint64_t max_positive = full >> 1;  // 2^(bits-1) - 1
  std::uint64_t raw = 0;
  if (literal->negative) {
    if (literal->magnitude > max_positive + 1) {
      Fail(QuoteForError(text) + " is " +
           RangeText(type, -static_cast<long double>(max_positive) - 1,
                     static_cast<long double>(max_positive)));
    }
    raw = ~literal->magnitude + 1;  // two's complement in 64 bits; EncodeLe keeps the low bytes
  } else if (literal->magnitude <= max_positive || (literal->hex && literal->magnitude <= full)) {
    raw = literal->magnitude;
  } else {
    Fail(
        QuoteForError(text) + " is " +
        RangeText(type, -static_cast<long double>(max_positive) - 1, static_cast<long double>(max_positive)));
  }
  return EncodeLe(raw, size);
}

template <typename Float>
Bytes EncodeReal(std::string_view text) {
  std::string_view digits = text;
  bool negative = false;
  if (!digits.empty() && (digits.front() == '+' || digits.front() == '-')) {
    negative = digits.front() == '-';
    digits.remove_prefix(1);
  }
  auto format = std::chars_format::general;
  if (digits.size() >= 2 && digits[0] == '0' && (digits[1] == 'x' || digits[1] == 'X')) {
    format = std::chars_format::hex;
    digits.remove_prefix(2);
  }
  // from_chars takes no sign of its own here: a second sign ("--1") must not slip through.
  if (digits.empty() || digits.front() == '-' || digits.front() == '+') Fail(NotANumber(text));
  Float value{};
  auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value, format);
  if (ec == std::errc::result_out_of_range) Fail(QuoteForError(text) + " is out of range for a REAL");
  if (ec != std::errc() || end != digits.data() + digits.size()) Fail(NotANumber(text));
  if (negative) value = -value;
  // One NaN: the file cannot spell NaN payloads, so every NaN reads back the same.
  if (std::isnan(value)) value = std::numeric_limits<Float>::quiet_NaN();
  return EncodeLe(value);
}

Bytes DecodeHex(std::string_view text) {
  std::string_view digits = text;
  if (digits.size() >= 2 && digits[0] == '0' && (digits[1] == 'x' || digits[1] == 'X'))
    digits.remove_prefix(2);
  Bytes out;
  int pending = -1;
  for (char c : digits) {
    if (c == ' ' || c == '\t') {
      if (pending >= 0) Fail(QuoteForError(text) + " is not hex bytes (odd number of digits)");
      continue;
    }
    int nibble = -1;
    if (c >= '0' && c <= '9') nibble = c - '0';
    if (c >= 'a' && c <= 'f') nibble = c - 'a' + 10;
    if (c >= 'A' && c <= 'F') nibble = c - 'A' + 10;
    if (nibble < 0) Fail(QuoteForError(text) + " is not hex bytes");
    if (pending < 0) {
      pending = nibble;
    } else {
      out.push_back(static_cast<std::uint8_t>(pending << 4 | nibble));
      pending = -1;
    }
  }
  if (pending >= 0) Fail(QuoteForError(text) + " is not hex bytes (odd number of digits)");
  return out;
}

}  // namespace

bool IsIntegerType(DataType type) {
  return (IsSigned(type) || IsUnsigned(type) || type == DataType::kTimeOfDay ||
          type == DataType::kTimeDifference) &&
         FixedSize(type).has_value();
}

EdsValue ParseEdsValue(DataType type, std::string_view text, bool allow_node_id) {
  if (type == DataType::kVisibleString) return EdsValue{ToBytes(text), false};
  std::string_view value = StripInlineComment(text);
  if (IsVariableLength(type)) return EdsValue{DecodeHex(value), false};
  if (type == DataType::kReal32) return EdsValue{EncodeReal<float>(value), false};
  if (type == DataType::kReal64) return EdsValue{EncodeReal<double>(value), false};
  if (!IsIntegerType(type)) Fail("values of data type " + std::string(ToString(type)) + " are not supported");

  auto at = FindNodeId(value);
  if (at == std::string_view::npos) return EdsValue{EncodeInteger(type, value), false};
  if (!allow_node_id) Fail(QuoteForError(value) + ": $NODEID is not allowed here");
  if (type == DataType::kBoolean) Fail(QuoteForError(value) + ": $NODEID needs an integer type, not BOOLEAN");
  auto before = TrimBlanks(value.substr(0, at));
  auto after = TrimBlanks(value.substr(at + kNodeId.size()));
  std::string_view constant = "0";
  if (before.empty() && after.empty()) {
    // "$NODEID" alone
  } else if (before.empty() && after.front() == '+') {
    constant = TrimBlanks(after.substr(1));
  } else if (after.empty() && before.back() == '+') {
    constant = TrimBlanks(before.substr(0, before.size() - 1));
  } else {
    Fail(QuoteForError(value) + " is not a number or a $NODEID+x formula");
  }
  if (constant.empty()) Fail(QuoteForError(value) + ": missing the number after '+'");
  return EdsValue{EncodeInteger(type, constant), true};
}

std::string FormatEdsValue(DataType type, std::span<const std::uint8_t> bytes, bool adds_node_id) {
  char buf[64];
  if (type == DataType::kVisibleString) return std::string(bytes.begin(), bytes.end());
  if (IsVariableLength(type) || !FixedSize(type)) {
    std::string out;
    for (auto b : bytes) {
      std::snprintf(buf, sizeof buf, "%02X", b);
      out += buf;
    }
    return out;
  }
  if (type == DataType::kReal32 || type == DataType::kReal64) {
    std::to_chars_result result{};
    if (type == DataType::kReal32) {
      float value = std::bit_cast<float>(static_cast<std::uint32_t>(DecodeUnsignedLe(bytes)));
      result = std::to_chars(buf, buf + sizeof buf, value);
    } else {
      double value = std::bit_cast<double>(DecodeUnsignedLe(bytes));
      result = std::to_chars(buf, buf + sizeof buf, value);
    }
    std::string text(buf, result.ptr);
    if (text == "-nan") text = "nan";
    return text;
  }
  std::string number;
  if (type == DataType::kBoolean) {
    std::snprintf(buf, sizeof buf, "%llu", static_cast<unsigned long long>(DecodeUnsignedLe(bytes)));
    number = buf;
  } else if (IsSigned(type)) {
    std::snprintf(buf, sizeof buf, "%lld", static_cast<long long>(DecodeSignedLe(bytes)));
    number = buf;
  } else {
    std::snprintf(buf, sizeof buf, "0x%0*llX", static_cast<int>(bytes.size() * 2),
                  static_cast<unsigned long long>(DecodeUnsignedLe(bytes)));
    number = buf;
  }
  if (!adds_node_id) return number;
  if (DecodeUnsignedLe(bytes) == 0) return std::string(kNodeId);
  return std::string(kNodeId) + "+" + number;
}

bool IsWritableText(std::string_view text) {
  if (!text.empty() &&
      (text.front() == ' ' || text.front() == '\t' || text.back() == ' ' || text.back() == '\t')) {
    return false;
  }
  // Exactly what LexIni accepts inside a value: tabs, but no other control character.
  return std::none_of(text.begin(), text.end(), [](char c) {
    auto byte = static_cast<unsigned char>(c);
    return (byte < 0x20 && byte != '\t') || byte == 0x7F;
  });
}

}  // namespace canfleet::canopen
