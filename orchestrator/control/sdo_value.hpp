#pragma once
/// @file SDO values as text, with the data type names CANopenNode's cocomm uses (CiA 309-3
/// ASCII gateway): b i8 i16 i32 i64 u8 u16 u32 u64 r32 r64 vs os d. The control API's SdoRead and
/// SdoWrite, the topology's `sdo` writes and the CLI share these rules.
///
/// The types are CiA 301 data types (canopen::DataType, one enum for the whole tree) and the values
/// go through the one value codec, in its gateway syntax (node/canopen/od/value_text.hpp); this
/// adds cocomm's names, the trimming and the messages, which name type and text.
///
/// Encoding (CiA 301 §7.1: every basic type little-endian):
///   b        "true"/"false" or "1"/"0"                        -> 1 byte, 01h/00h
///   i8..i64  decimal or 0x hex, optional sign, range-checked  -> 1, 2, 4, 8 bytes, two's complement
///   u8..u64  decimal or 0x hex, range-checked                 -> 1, 2, 4, 8 bytes
///   r32 r64  decimal or exponent notation, "inf", "nan"       -> IEEE 754 binary32/binary64
///   vs       the text itself (no terminating NUL)
///   os, d    hex bytes, spaces allowed: "0a0b0c", "0A 0B 0C"
///   ""       (no type) as os: hex bytes
///
/// Formatting gives the text that encodes back to the same bytes, except that vs drops trailing
/// NULs and shows other control bytes as \xNN; os, d and "" give upper-case hex bytes separated by
/// spaces ("0A 0B 0C"), as cocomm prints them.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "node/canopen/od/types.hpp"

namespace canfleet::control {

/// A type as cocomm names it: a CiA 301 data type ("u16" is UNSIGNED16), or no type at all (""),
/// which reads and shows raw bytes as hex. SdoType::kUnsigned16 is canopen::DataType::kUnsigned16.
class SdoType {
 public:
  using enum canopen::DataType;

  /// No type: raw bytes as hex.
  constexpr SdoType() = default;
  /// A data type is an SDO type.
  constexpr SdoType(canopen::DataType type) : type_(type) {}  // NOLINT(google-explicit-constructor)

  /// The CiA 301 type; nullopt for raw bytes.
  constexpr std::optional<canopen::DataType> data_type() const { return type_; }

  friend constexpr bool operator==(const SdoType&, const SdoType&) = default;

  /// No type given: raw bytes as hex.
  static const SdoType kHex;

 private:
  std::optional<canopen::DataType> type_;
};

inline constexpr SdoType SdoType::kHex{};

/// The type named `name` ("u16"; "" is kHex), or nullopt for an unknown name.
std::optional<SdoType> ParseSdoType(std::string_view name);
/// The cocomm name of `type` ("u16"; "" for kHex and for data types cocomm has no name for).
std::string_view SdoTypeName(SdoType type);
/// Every type name, for help and error texts: "b i8 i16 i32 i64 u8 u16 u32 u64 r32 r64 vs os d".
std::string_view SdoTypeNames();
/// Bytes of a value of a fixed-size type (u16: 2); 0 for vs, os, d and kHex.
std::size_t SdoTypeSize(SdoType type);

/// A value that does not fit its type, or an unknown type name. what() is one line naming the
/// type and the text: `u8 value "300" is out of range (0..255)`.
class SdoValueError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// The type named `name`; throws SdoValueError for an unknown name (`unknown SDO type "u7"
/// (expected one of b i8 ...)`). Checks a request's type before anything goes on the bus.
SdoType RequireSdoType(std::string_view name);

/// The bytes to download for `text` read as `type` (a name, as ParseSdoType). Throws
/// SdoValueError.
std::vector<std::uint8_t> EncodeSdoValue(std::string_view type, std::string_view text);
std::vector<std::uint8_t> EncodeSdoValue(SdoType type, std::string_view text);

/// Uploaded bytes shown as `type`. Throws SdoValueError for an unknown type and when the size
/// does not fit the type: `u32 is 4 bytes, got 1 (01)`.
std::string FormatSdoValue(std::string_view type, std::span<const std::uint8_t> bytes);
std::string FormatSdoValue(SdoType type, std::span<const std::uint8_t> bytes);

/// Upper-case hex bytes separated by spaces ("0A 0B 0C"; "" for no bytes).
std::string HexBytes(std::span<const std::uint8_t> bytes);

}  // namespace canfleet::control
