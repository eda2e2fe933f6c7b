#pragma once
/// @file Typed values as EDS/DCF files spell them (DefaultValue, ParameterValue, LowLimit,
/// HighLimit), and back: integers with their type's range, "$NODEID" formulas, REAL32/REAL64,
/// VISIBLE_STRING as text, OCTET_STRING/UNICODE_STRING/DOMAIN as hex digits. The values
/// themselves go through the one value codec (node/canopen/od/value_text.hpp, ValueSyntax::kEds);
/// this adds $NODEID, inline comments and the reader's messages. (IsIntegerType is there too.)

#include <span>
#include <stdexcept>
#include <string>
#include <string_view>

#include "node/canopen/od/types.hpp"
#include "node/canopen/od/value.hpp"
#include "node/canopen/od/value_text.hpp"

namespace canfleet::canopen {

/// A value that cannot be parsed; what() is the detail for an EdsError (the reader adds where).
class EdsValueError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A parsed value, encoded like SubObject::value.
struct EdsValue {
  Bytes bytes;
  /// CiA 306 "$NODEID+x" / "x+$NODEID" / "$NODEID": `bytes` holds x; the node-ID is added later.
  bool adds_node_id = false;
};

/// Parses `text` (a trimmed value, not empty) as a value of `type`, a known type (IsKnown).
/// @param allow_node_id false where $NODEID has no meaning
/// @throws EdsValueError with a message such as `"0xZZ" is not a number`
EdsValue ParseEdsValue(DataType type, std::string_view text, bool allow_node_id);

/// Spells a value for an EDS/DCF: unsigned integers as 0x-hex padded to the type's width,
/// BOOLEAN and signed integers in decimal, reals in the shortest form that reads back to the same
/// bits, strings as text, octet strings and domains as hex digits. With `adds_node_id`, an
/// integer is written as "$NODEID+x" (or "$NODEID" when x is 0).
std::string FormatEdsValue(DataType type, std::span<const std::uint8_t> bytes, bool adds_node_id);

/// True if `text` survives being written as an EDS value or name and read back: no control
/// character but tab (the file is line-based) and no leading or trailing blank (values are
/// trimmed).
bool IsWritableText(std::string_view text);

}  // namespace canfleet::canopen
