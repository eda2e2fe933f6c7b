#pragma once
/// @file Typed values as text and back: the one codec between a CiA 301 data type's bytes and the
/// two ways canfleet spells them. EDS/DCF files (node/canopen/eds/eds_value.hpp adds their
/// "$NODEID" formulas and messages) and the control API's SDO values
/// (orchestrator/control/sdo_value.hpp adds cocomm's type names and messages) both call this.
///
/// A text that is not a value of its type throws ValueTextError, which says what is wrong as data
/// (not a number, out of range...); each caller phrases it in its own words.

#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>

#include "node/canopen/od/types.hpp"
#include "node/canopen/od/value.hpp"

namespace canfleet::canopen {

/// How a text spells values.
enum class ValueSyntax : std::uint8_t {
  /// CiA 306 §4.2 (EDS and DCF files). Integers: decimal, 0x hex or leading-0 octal with an
  /// optional sign; a signed type also takes hex up to its full width as two's complement
  /// (0xFFFF = -1 for INTEGER16), as vendor tools write limits; BOOLEAN is the integer 0 or 1.
  /// Reals: decimal, exponent or 0x hex-float notation, "inf", "nan" (one NaN). OCTET_STRING,
  /// UNICODE_STRING, DOMAIN: hex digits, optionally after 0x, blanks between bytes.
  /// Written: unsigned as 0x hex padded to the type's width, BOOLEAN and signed in decimal, reals
  /// in the shortest form that reads back to the same bits, hex digits without blanks.
  kEds,
  /// CiA 309-3 ASCII gateway as CANopenNode's cocomm spells it. Integers: decimal or 0x hex with
  /// an optional sign, range-checked. BOOLEAN: true, false, 1 or 0. Reals: decimal or exponent
  /// notation, "inf", "nan". Octet strings and domains: hex bytes, blanks or ':' between bytes.
  /// Written: integers in decimal, BOOLEAN as true/false, reals in the shortest form, visible
  /// strings without trailing NULs and with other control bytes as \xNN, hex bytes as "0A 0B 0C";
  /// a fixed-size type must have exactly its size.
  kGateway,
};

/// Why a text (or bytes) is not a value of its type.
class ValueTextError : public std::invalid_argument {
 public:
  enum class Kind : std::uint8_t {
    kNotANumber,   ///< not an integer / real literal of the syntax
    kOutOfRange,   ///< a number outside the type; range(): "0..255", "-128..127" (integers)
    kNotBoolean,   ///< kGateway: not true, false, 1 or 0
    kNotHex,       ///< a character that is not a hex digit
    kOddHex,       ///< an odd number of hex digits (kEds: also a blank inside a byte)
    kSplitByte,    ///< kGateway: a separator between the two digits of a byte
    kWrongSize,    ///< formatting: bytes of another size than the type's; range(): "4"
    kUnsupported,  ///< a type the codec has no spelling for
  };
  ValueTextError(Kind kind, std::string range = {});
  Kind kind() const { return kind_; }
  /// kOutOfRange: the type's range for integers, empty for reals; kWrongSize: the type's size.
  const std::string& range() const { return range_; }

 private:
  Kind kind_;
  std::string range_;
};

/// An integer literal, before any type's range applies.
struct IntegerLiteral {
  bool negative = false;
  std::uint64_t magnitude = 0;
  bool hex = false;       ///< written as 0x...: kEds lets a signed type take it as two's complement
  bool overflow = false;  ///< kGateway: more than 64 bits (out of range); kEds gives nullopt instead
};

/// The whole of `text` (no blanks inside) read as an integer literal of `syntax`; nullopt if it is
/// not one (kEds: also when it does not fit 64 bits).
std::optional<IntegerLiteral> ReadIntegerLiteral(std::string_view text, ValueSyntax syntax);

/// `text` (already trimmed where the syntax trims) as the bytes of a value of `type`, a known
/// type (IsKnown). VISIBLE_STRING takes the text as it is.
/// @throws ValueTextError
Bytes ParseValueText(DataType type, std::string_view text, ValueSyntax syntax);

/// `bytes` of a value of `type` as `syntax` writes it.
/// @throws ValueTextError (kGateway only: kWrongSize, kNotBoolean for a BOOLEAN other than 0 or 1)
std::string FormatValueText(DataType type, std::span<const std::uint8_t> bytes, ValueSyntax syntax);

/// True for the types whose values are integers (BOOLEAN, INTEGERn, UNSIGNEDn, TIME_OF_DAY and
/// TIME_DIFFERENCE are not: the latter two have no integer spelling).
bool IsIntegerType(DataType type);

}  // namespace canfleet::canopen
