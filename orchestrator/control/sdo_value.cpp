#include "orchestrator/control/sdo_value.hpp"

#include <array>

#include "node/canopen/od/value_text.hpp"

namespace canfleet::control {

namespace {

using canopen::DataType;
using canopen::ValueSyntax;
using canopen::ValueTextError;
using Bytes = std::vector<std::uint8_t>;

struct TypeName {
  SdoType type;
  std::string_view name;
};

/// cocomm's names of the CiA 301 types it knows.
constexpr std::array<TypeName, 15> kNames{{
    {SdoType::kHex, ""},
    {DataType::kBoolean, "b"},
    {DataType::kInteger8, "i8"},
    {DataType::kInteger16, "i16"},
    {DataType::kInteger32, "i32"},
    {DataType::kInteger64, "i64"},
    {DataType::kUnsigned8, "u8"},
    {DataType::kUnsigned16, "u16"},
    {DataType::kUnsigned32, "u32"},
    {DataType::kUnsigned64, "u64"},
    {DataType::kReal32, "r32"},
    {DataType::kReal64, "r64"},
    {DataType::kVisibleString, "vs"},
    {DataType::kOctetString, "os"},
    {DataType::kDomain, "d"},
}};

/// What the codec works with: raw bytes are an octet string.
DataType CodecType(SdoType type) {
  return type.data_type().value_or(DataType::kOctetString);
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

[[noreturn]] void Error(std::string message) {
  throw SdoValueError(std::move(message));
}

std::string UnknownType(std::string_view type) {
  return "unknown SDO type \"" + std::string(type) + "\" (expected one of " + std::string(SdoTypeNames()) +
         ")";
}

/// The codec's complaint about `text` as a `type` value, in cocomm's words.
[[noreturn]] void Refuse(SdoType type, std::string_view text, const ValueTextError& e) {
  const std::string_view name = SdoTypeName(type);
  const DataType data_type = CodecType(type);
  const bool real = canopen::IsReal(data_type);
  switch (e.kind()) {
    case ValueTextError::Kind::kOutOfRange:
      if (real)
        Error(Quoted(name, text) + " is out of range (" + std::string(name) + " magnitudes are " +
              (data_type == DataType::kReal32 ? "1.4e-45..3.4e38" : "4.9e-324..1.8e308") + ", or 0)");
      Error(Quoted(name, text) + " is out of range (" + e.range() + ")");
    case ValueTextError::Kind::kNotBoolean:
      Error(Quoted(name, text) + " is not a boolean (true, false, 1 or 0)");
    case ValueTextError::Kind::kSplitByte:
      Error(Quoted(name, text) + ": a byte needs two hex digits (\"0a\", not \"a\")");
    case ValueTextError::Kind::kNotHex:
      Error(Quoted(name, text) + " is not hex bytes (e.g. \"0a0b0c\" or \"0A 0B 0C\")");
    case ValueTextError::Kind::kOddHex:
      Error(Quoted(name, text) + ": odd number of hex digits");
    default:
      if (real) Error(Quoted(name, text) + " is not a number (e.g. 1.5, -2e3, inf, nan)");
      Error(Quoted(name, text) + " is not a number (decimal, or hex as 0x1A" +
            std::string(canopen::IsSigned(data_type) ? ", negative with -" : "") + ")");
  }
}

}  // namespace

std::optional<SdoType> ParseSdoType(std::string_view name) {
  for (const TypeName& t : kNames)
    if (t.name == name) return t.type;
  return std::nullopt;
}

std::string_view SdoTypeName(SdoType type) {
  for (const TypeName& t : kNames)
    if (t.type == type) return t.name;
  return "";
}

std::string_view SdoTypeNames() {
  return "b i8 i16 i32 i64 u8 u16 u32 u64 r32 r64 vs os d";
}

std::size_t SdoTypeSize(SdoType type) {
  return type.data_type() ? canopen::FixedSize(*type.data_type()).value_or(0) : 0;
}

std::string HexBytes(std::span<const std::uint8_t> bytes) {
  return canopen::FormatValueText(DataType::kOctetString, bytes, ValueSyntax::kGateway);
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
  const DataType data_type = CodecType(type);
  // A visible string is the text itself; anything else may have blanks around it. A boolean's
  // message quotes the text as given, the others the trimmed value.
  const std::string_view value = data_type == DataType::kVisibleString ? text : Trim(text);
  try {
    return canopen::ParseValueText(data_type, value, ValueSyntax::kGateway);
  } catch (const ValueTextError& e) {
    Refuse(type, data_type == DataType::kBoolean ? text : value, e);
  }
}

std::string FormatSdoValue(std::string_view type, std::span<const std::uint8_t> bytes) {
  return FormatSdoValue(RequireSdoType(type), bytes);
}

std::string FormatSdoValue(SdoType type, std::span<const std::uint8_t> bytes) {
  try {
    return canopen::FormatValueText(CodecType(type), bytes, ValueSyntax::kGateway);
  } catch (const ValueTextError& e) {
    const std::string name(SdoTypeName(type));
    if (e.kind() == ValueTextError::Kind::kNotBoolean) Error(name + " is 00 or 01, got " + HexBytes(bytes));
    const std::string& size = e.range();
    Error(name + " is " + size + (size == "1" ? " byte" : " bytes") + ", got " +
          std::to_string(bytes.size()) + (bytes.empty() ? "" : " (" + HexBytes(bytes) + ")"));
  }
}

}  // namespace canfleet::control
