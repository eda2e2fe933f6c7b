#include "orchestrator/control/sdo_value.hpp"

#include <array>
#include <bit>
#include <charconv>
#include <cstring>
#include <limits>

namespace canfleet::control {

namespace {

struct TypeInfo {
  SdoType type;
  std::string_view name;
  std::size_t size;  ///< 0: variable
};

constexpr std::array<TypeInfo, 15> kTypes{{
    {SdoType::kHex, "", 0},
    {SdoType::kBoolean, "b", 1},
    {SdoType::kInteger8, "i8", 1},
    {SdoType::kInteger16, "i16", 2},
    {SdoType::kInteger32, "i32", 4},
    {SdoType::kInteger64, "i64", 8},
    {SdoType::kUnsigned8, "u8", 1},
    {SdoType::kUnsigned16, "u16", 2},
    {SdoType::kUnsigned32, "u32", 4},
    {SdoType::kUnsigned64, "u64", 8},
    {SdoType::kReal32, "r32", 4},
    {SdoType::kReal64, "r64", 8},
    {SdoType::kVisibleString, "vs", 0},
    {SdoType::kOctetString, "os", 0},
    {SdoType::kDomain, "d", 0},
}};

const TypeInfo& Info(SdoType type) {
  return kTypes[static_cast<std::size_t>(type)];
}

bool IsSigned(SdoType t) {
  return t == SdoType::kInteger8 || t == SdoType::kInteger16 || t == SdoType::kInteger32 ||
         t == SdoType::kInteger64;
}

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t'))
    s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t'))
    s.remove_suffix(1);
  return s;
}

std::string Quoted(std::string_view type, std::string_view text) {
  return std::string(type.empty() ? "hex" : type) + " value \"" + std::string(text) + "\"";
}

using Bytes = std::vector<std::uint8_t>;

[[noreturn]] void Error(std::string message) {
  throw SdoValueError(std::move(message));
}

Bytes LittleEndian(std::uint64_t value, std::size_t size) {
  Bytes out(size);
  for (std::size_t i = 0; i < size; ++i)
    out[i] = static_cast<std::uint8_t>(value >> (8 * i));
  return out;
}

std::uint64_t ReadLittleEndian(std::span<const std::uint8_t> bytes) {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < bytes.size(); ++i)
    v |= std::uint64_t{bytes[i]} << (8 * i);
  return v;
}

/// Decimal or 0x hex digits into a magnitude; false when not a number, `overflow` when it does
/// not fit 64 bits.
bool ParseMagnitude(std::string_view digits, std::uint64_t& value, bool& overflow) {
  int base = 10;
  if (digits.size() > 2 && digits[0] == '0' && (digits[1] == 'x' || digits[1] == 'X')) {
    base = 16;
    digits.remove_prefix(2);
  }
  if (digits.empty() || digits[0] == '+' || digits[0] == '-') return false;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value, base);
  if (end != digits.data() + digits.size()) return false;
  overflow = ec == std::errc::result_out_of_range;
  return ec == std::errc() || overflow;
}

Bytes EncodeInteger(SdoType type, std::string_view text) {
  const std::string_view name = Info(type).name;
  const std::size_t size = Info(type).size;
  const unsigned bits = static_cast<unsigned>(size * 8);
  std::string_view digits = text;
  bool negative = false;
  if (!digits.empty() && (digits[0] == '-' || digits[0] == '+')) {
    negative = digits[0] == '-';
    digits.remove_prefix(1);
  }
  std::uint64_t magnitude = 0;
  bool overflow = false;
  const bool is_signed = IsSigned(type);
  const std::uint64_t max_positive = is_signed    ? (std::uint64_t{1} << (bits - 1)) - 1
                                     : bits == 64 ? std::numeric_limits<std::uint64_t>::max()
                                                  : (std::uint64_t{1} << bits) - 1;
  const std::string range = is_signed ? std::to_string(-static_cast<std::int64_t>(max_positive) - 1) + ".." +
                                            std::to_string(max_positive)
                                      : "0.." + std::to_string(max_positive);
  if (!ParseMagnitude(digits, magnitude, overflow))
    Error(Quoted(name, text) + " is not a number (decimal, or hex as 0x1A" +
          std::string(is_signed ? ", negative with -" : "") + ")");
  const std::string out_of_range = Quoted(name, text) + " is out of range (" + range + ")";
  if (overflow) Error(out_of_range);
  if (!is_signed) {
    if ((negative && magnitude != 0) || magnitude > max_positive) Error(out_of_range);
    return LittleEndian(magnitude, size);
  }
  if (negative ? magnitude > max_positive + 1 : magnitude > max_positive) Error(out_of_range);
  const std::uint64_t pattern = negative ? ~magnitude + 1 : magnitude;  // two's complement
  return LittleEndian(pattern, size);
}

template <class F>
Bytes EncodeReal(std::string_view name, std::string_view text) {
  std::string_view digits = text;
  if (!digits.empty() && digits[0] == '+') digits.remove_prefix(1);
  F value{};
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (digits.empty() || end != digits.data() + digits.size() ||
      (ec != std::errc() && ec != std::errc::result_out_of_range))
    Error(Quoted(name, text) + " is not a number (e.g. 1.5, -2e3, inf, nan)");
  // Too large, or so small it would round to zero.
  if (ec == std::errc::result_out_of_range)
    Error(Quoted(name, text) + " is out of range (" + std::string(name) + " magnitudes are " +
          (sizeof(F) == 4 ? "1.4e-45..3.4e38" : "4.9e-324..1.8e308") + ", or 0)");
  using U = std::conditional_t<sizeof(F) == 4, std::uint32_t, std::uint64_t>;
  return LittleEndian(std::bit_cast<U>(value), sizeof(F));
}

int HexDigit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

Bytes EncodeHex(std::string_view name, std::string_view text) {
  Bytes out;
  int high = -1;
  for (const char c : text) {
    if (c == ' ' || c == '\t' || c == ':') {
      if (high >= 0) Error(Quoted(name, text) + ": a byte needs two hex digits (\"0a\", not \"a\")");
      continue;
    }
    const int d = HexDigit(c);
    if (d < 0) Error(Quoted(name, text) + " is not hex bytes (e.g. \"0a0b0c\" or \"0A 0B 0C\")");
    if (high < 0) {
      high = d;
    } else {
      out.push_back(static_cast<std::uint8_t>(high << 4 | d));
      high = -1;
    }
  }
  if (high >= 0) Error(Quoted(name, text) + ": odd number of hex digits");
  return out;
}

std::string UnknownType(std::string_view type) {
  return "unknown SDO type \"" + std::string(type) + "\" (expected one of " + std::string(SdoTypeNames()) +
         ")";
}

template <class F>
std::string RealText(F value) {
  std::array<char, 64> buffer{};
  const auto [end, ec] = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  return ec == std::errc() ? std::string(buffer.data(), end) : std::string("?");
}

std::string VisibleText(std::span<const std::uint8_t> bytes) {
  std::size_t n = bytes.size();
  while (n > 0 && bytes[n - 1] == 0)
    --n;
  std::string out;
  out.reserve(n);
  constexpr const char* kHex = "0123456789ABCDEF";
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t c = bytes[i];
    if (c < 0x20 || c == 0x7F) {
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 0xF];
    } else {
      out += static_cast<char>(c);
    }
  }
  return out;
}

}  // namespace

std::optional<SdoType> ParseSdoType(std::string_view name) {
  for (const TypeInfo& t : kTypes)
    if (t.name == name) return t.type;
  return std::nullopt;
}

std::string_view SdoTypeName(SdoType type) {
  return Info(type).name;
}

std::string_view SdoTypeNames() {
  return "b i8 i16 i32 i64 u8 u16 u32 u64 r32 r64 vs os d";
}

std::size_t SdoTypeSize(SdoType type) {
  return Info(type).size;
}

std::string HexBytes(std::span<const std::uint8_t> bytes) {
  constexpr const char* kHex = "0123456789ABCDEF";
  std::string out;
  out.reserve(bytes.size() * 3);
  for (const std::uint8_t b : bytes) {
    if (!out.empty()) out += ' ';
    out += kHex[b >> 4];
    out += kHex[b & 0xF];
  }
  return out;
}

SdoType RequireSdoType(std::string_view name) {
  const auto t = ParseSdoType(name);
  if (!t) Error(UnknownType(name));
  return *t;
}

Bytes EncodeSdoValue(std::string_view type, std::string_view text) {
  return EncodeSdoValue(RequireSdoType(type), text);
}

Bytes EncodeSdoValue(SdoType type, std::string_view text) {
  const std::string_view name = Info(type).name;
  if (type == SdoType::kVisibleString) return Bytes(text.begin(), text.end());
  const std::string_view value = Trim(text);
  switch (type) {
    case SdoType::kBoolean:
      if (value == "true" || value == "1") return {1};
      if (value == "false" || value == "0") return {0};
      Error(Quoted(name, text) + " is not a boolean (true, false, 1 or 0)");
    case SdoType::kReal32:
      return EncodeReal<float>(name, value);
    case SdoType::kReal64:
      return EncodeReal<double>(name, value);
    case SdoType::kHex:
    case SdoType::kOctetString:
    case SdoType::kDomain:
      return EncodeHex(name, value);
    default:
      return EncodeInteger(type, value);
  }
}

std::string FormatSdoValue(std::string_view type, std::span<const std::uint8_t> bytes) {
  return FormatSdoValue(RequireSdoType(type), bytes);
}

std::string FormatSdoValue(SdoType type, std::span<const std::uint8_t> bytes) {
  const std::size_t size = Info(type).size;
  if (size != 0 && bytes.size() != size)
    Error(std::string(Info(type).name) + " is " + std::to_string(size) + (size == 1 ? " byte" : " bytes") +
          ", got " + std::to_string(bytes.size()) + (bytes.empty() ? "" : " (" + HexBytes(bytes) + ")"));
  const std::uint64_t raw = ReadLittleEndian(bytes);
  switch (type) {
    case SdoType::kBoolean:
      if (raw > 1) Error("b is 00 or 01, got " + HexBytes(bytes));
      return raw != 0 ? "true" : "false";
    case SdoType::kUnsigned8:
    case SdoType::kUnsigned16:
    case SdoType::kUnsigned32:
    case SdoType::kUnsigned64:
      return std::to_string(raw);
    case SdoType::kInteger8:
    case SdoType::kInteger16:
    case SdoType::kInteger32:
    case SdoType::kInteger64: {
      const unsigned shift = static_cast<unsigned>(64 - size * 8);
      // Sign-extend: move the type's sign bit to bit 63, then shift back arithmetically.
      const std::int64_t value = static_cast<std::int64_t>(raw << shift) >> shift;
      return std::to_string(value);
    }
    case SdoType::kReal32:
      return RealText(std::bit_cast<float>(static_cast<std::uint32_t>(raw)));
    case SdoType::kReal64:
      return RealText(std::bit_cast<double>(raw));
    case SdoType::kVisibleString:
      return VisibleText(bytes);
    case SdoType::kHex:
    case SdoType::kOctetString:
    case SdoType::kDomain:
      return HexBytes(bytes);
  }
  Error("unknown SDO type");
}

}  // namespace canfleet::control
