#include "node/canopen/od/value_text.hpp"

#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <limits>
#include <optional>
#include <type_traits>

namespace canfleet::canopen {

namespace {

using Kind = ValueTextError::Kind;

[[noreturn]] void Fail(Kind kind, std::string range = {}) {
  throw ValueTextError(kind, std::move(range));
}

int HexDigit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

bool HasHexPrefix(std::string_view text) {
  return text.size() >= 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X');
}

// ---- integers ---------------------------------------------------------------------------------

}  // namespace

std::optional<IntegerLiteral> ReadIntegerLiteral(std::string_view text, ValueSyntax syntax) {
  IntegerLiteral out;
  if (!text.empty() && (text.front() == '+' || text.front() == '-')) {
    out.negative = text.front() == '-';
    text.remove_prefix(1);
  }
  unsigned base = 10;
  // kEds: a leading 0 is octal, as in C (CiA 306 §4.2); the gateway reads "010" as ten. A lone
  // "0x" is no number in either.
  if (syntax == ValueSyntax::kEds ? HasHexPrefix(text) : text.size() > 2 && HasHexPrefix(text)) {
    base = 16;
    out.hex = true;
    text.remove_prefix(2);
  } else if (syntax == ValueSyntax::kEds && text.size() >= 2 && text[0] == '0') {
    base = 8;
    text.remove_prefix(1);
  }
  if (text.empty()) return std::nullopt;
  constexpr auto kMax = std::numeric_limits<std::uint64_t>::max();
  for (const char c : text) {
    const int digit = HexDigit(c);
    if (digit < 0 || static_cast<unsigned>(digit) >= base) return std::nullopt;
    const auto d = static_cast<unsigned>(digit);
    if (out.overflow || out.magnitude > (kMax - d) / base) {
      out.overflow = true;
      continue;
    }
    out.magnitude = out.magnitude * base + d;
  }
  if (out.overflow && syntax == ValueSyntax::kEds) return std::nullopt;
  return out;
}

namespace {

/// The range of an integer type as messages print it: "0..255", "-128..127".
std::string RangeText(bool is_signed, std::uint64_t full) {
  if (!is_signed) return "0.." + std::to_string(full);
  const std::uint64_t max_positive = full >> 1;
  return "-" + std::to_string(max_positive + 1) + ".." + std::to_string(max_positive);
}

Bytes EncodeInteger(DataType type, std::string_view text, ValueSyntax syntax) {
  const std::optional<IntegerLiteral> literal = ReadIntegerLiteral(text, syntax);
  if (!literal) Fail(Kind::kNotANumber);
  const std::size_t size = *FixedSize(type);
  const unsigned bits = type == DataType::kBoolean ? 1U : static_cast<unsigned>(size * 8);
  const std::uint64_t full = bits == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << bits) - 1;
  const bool is_signed = IsSigned(type);
  const std::string range = RangeText(is_signed, full);
  if (literal->overflow) Fail(Kind::kOutOfRange, range);
  if (!is_signed) {
    if ((literal->negative && literal->magnitude != 0) || literal->magnitude > full)
      Fail(Kind::kOutOfRange, range);
    return EncodeLe(literal->magnitude, size);
  }
  const std::uint64_t max_positive = full >> 1;  // 2^(bits-1) - 1
  if (literal->negative) {
    if (literal->magnitude > max_positive + 1) Fail(Kind::kOutOfRange, range);
    return EncodeLe(~literal->magnitude + 1, size);  // two's complement; EncodeLe keeps the low bytes
  }
  // kEds: hex up to the full width is two's complement (0xFF = -1 for INTEGER8).
  const bool twos_complement = syntax == ValueSyntax::kEds && literal->hex && literal->magnitude <= full;
  if (literal->magnitude > max_positive && !twos_complement) Fail(Kind::kOutOfRange, range);
  return EncodeLe(literal->magnitude, size);
}

Bytes EncodeBoolean(std::string_view text) {
  if (text == "true" || text == "1") return {1};
  if (text == "false" || text == "0") return {0};
  Fail(Kind::kNotBoolean);
}

// ---- reals ------------------------------------------------------------------------------------

template <typename Float>
Bytes EncodeReal(std::string_view text, ValueSyntax syntax) {
  std::string_view digits = text;
  bool negative = false;
  if (!digits.empty() && (digits.front() == '+' || digits.front() == '-')) {
    negative = digits.front() == '-';
    digits.remove_prefix(1);
  }
  auto format = std::chars_format::general;
  if (syntax == ValueSyntax::kEds && HasHexPrefix(digits)) {
    format = std::chars_format::hex;
    digits.remove_prefix(2);
  }
  // from_chars takes no sign of its own here: a second sign ("--1") must not slip through.
  if (digits.empty() || digits.front() == '-' || digits.front() == '+') Fail(Kind::kNotANumber);
  Float value{};
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value, format);
  if (end != digits.data() + digits.size() || (ec != std::errc() && ec != std::errc::result_out_of_range))
    Fail(Kind::kNotANumber);
  // Too large, or so small it would round to zero.
  if (ec == std::errc::result_out_of_range) Fail(Kind::kOutOfRange);
  if (negative) value = -value;
  // kEds: one NaN, since the file cannot spell NaN payloads and every NaN must read back the same.
  if (syntax == ValueSyntax::kEds && std::isnan(value)) value = std::numeric_limits<Float>::quiet_NaN();
  return EncodeLe(value);
}

template <typename Float>
std::string RealText(Float value, ValueSyntax syntax) {
  std::array<char, 64> buffer{};
  const auto [end, ec] = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  if (ec != std::errc()) return "?";
  std::string text(buffer.data(), end);
  if (syntax == ValueSyntax::kEds && text == "-nan") text = "nan";
  return text;
}

// ---- byte strings -----------------------------------------------------------------------------

Bytes DecodeHex(std::string_view text, ValueSyntax syntax) {
  const bool eds = syntax == ValueSyntax::kEds;
  if (eds && HasHexPrefix(text)) text.remove_prefix(2);
  Bytes out;
  int high = -1;
  for (const char c : text) {
    if (c == ' ' || c == '\t' || (!eds && c == ':')) {
      if (high >= 0) Fail(eds ? Kind::kOddHex : Kind::kSplitByte);
      continue;
    }
    const int nibble = HexDigit(c);
    if (nibble < 0) Fail(Kind::kNotHex);
    if (high < 0) {
      high = nibble;
    } else {
      out.push_back(static_cast<std::uint8_t>(high << 4 | nibble));
      high = -1;
    }
  }
  if (high >= 0) Fail(Kind::kOddHex);
  return out;
}

constexpr const char* kHexDigits = "0123456789ABCDEF";

/// "01AB" (kEds) or "01 AB" (kGateway).
std::string HexText(std::span<const std::uint8_t> bytes, ValueSyntax syntax) {
  std::string out;
  out.reserve(bytes.size() * 3);
  for (const std::uint8_t b : bytes) {
    if (syntax == ValueSyntax::kGateway && !out.empty()) out += ' ';
    out += kHexDigits[b >> 4];
    out += kHexDigits[b & 0xF];
  }
  return out;
}

/// kGateway: the text without its trailing NULs, other control bytes as \xNN.
std::string VisibleText(std::span<const std::uint8_t> bytes) {
  std::size_t n = bytes.size();
  while (n > 0 && bytes[n - 1] == 0)
    --n;
  std::string out;
  out.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t c = bytes[i];
    if (c < 0x20 || c == 0x7F) {
      out += "\\x";
      out += kHexDigits[c >> 4];
      out += kHexDigits[c & 0xF];
    } else {
      out += static_cast<char>(c);
    }
  }
  return out;
}

}  // namespace

ValueTextError::ValueTextError(Kind kind, std::string range)
    : std::invalid_argument("value text error"), kind_(kind), range_(std::move(range)) {}

bool IsIntegerType(DataType type) {
  return (IsSigned(type) || IsUnsigned(type) || type == DataType::kTimeOfDay ||
          type == DataType::kTimeDifference) &&
         FixedSize(type).has_value();
}

Bytes ParseValueText(DataType type, std::string_view text, ValueSyntax syntax) {
  if (type == DataType::kVisibleString) return ToBytes(text);
  if (IsVariableLength(type)) return DecodeHex(text, syntax);
  if (type == DataType::kReal32) return EncodeReal<float>(text, syntax);
  if (type == DataType::kReal64) return EncodeReal<double>(text, syntax);
  if (type == DataType::kBoolean && syntax == ValueSyntax::kGateway) return EncodeBoolean(text);
  if (!IsIntegerType(type)) Fail(Kind::kUnsupported);
  return EncodeInteger(type, text, syntax);
}

std::string FormatValueText(DataType type, std::span<const std::uint8_t> bytes, ValueSyntax syntax) {
  const bool gateway = syntax == ValueSyntax::kGateway;
  const std::optional<std::size_t> size = FixedSize(type);
  if (gateway && size && bytes.size() != *size) Fail(Kind::kWrongSize, std::to_string(*size));
  if (type == DataType::kVisibleString)
    return gateway ? VisibleText(bytes) : std::string(bytes.begin(), bytes.end());
  if (IsVariableLength(type) || !size) return HexText(bytes, syntax);
  const std::uint64_t raw = DecodeUnsignedLe(bytes);
  if (type == DataType::kReal32)
    return RealText(std::bit_cast<float>(static_cast<std::uint32_t>(raw)), syntax);
  if (type == DataType::kReal64) return RealText(std::bit_cast<double>(raw), syntax);
  if (type == DataType::kBoolean && gateway) {
    if (raw > 1) Fail(Kind::kNotBoolean);
    return raw != 0 ? "true" : "false";
  }
  if (IsSigned(type)) return std::to_string(DecodeSignedLe(bytes));
  if (gateway || type == DataType::kBoolean) return std::to_string(raw);
  // kEds: unsigned as 0x hex, padded to the type's width.
  std::string out = "0x";
  for (std::size_t i = bytes.size(); i-- > 0;) {
    out += kHexDigits[bytes[i] >> 4];
    out += kHexDigits[bytes[i] & 0xF];
  }
  return out;
}

}  // namespace canfleet::canopen
