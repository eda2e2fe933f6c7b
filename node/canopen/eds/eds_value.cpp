#include "node/canopen/eds/eds_value.hpp"

#include <algorithm>
#include <cctype>

#include "node/canopen/eds/eds_error.hpp"
#include "node/canopen/eds/eds_number.hpp"
#include "node/canopen/eds/ini_lexer.hpp"

namespace canfleet::canopen {
namespace {

constexpr std::string_view kNodeId = "$NODEID";

[[noreturn]] void Fail(std::string detail) {
  throw EdsValueError(std::move(detail));
}

std::size_t FindNodeId(std::string_view text) {
  auto it = std::search(text.begin(), text.end(), kNodeId.begin(), kNodeId.end(), [](char a, char b) {
    return std::toupper(static_cast<unsigned char>(a)) == static_cast<unsigned char>(b);
  });
  return it == text.end() ? std::string_view::npos : static_cast<std::size_t>(it - text.begin());
}

/// The value codec (node/canopen/od/value_text.hpp) in CiA 306 syntax, its complaints in the
/// reader's words: `"300" is out of range for UNSIGNED8 (0..255)`.
Bytes Encode(DataType type, std::string_view text) {
  try {
    return ParseValueText(type, text, ValueSyntax::kEds);
  } catch (const ValueTextError& e) {
    const std::string quoted = QuoteForError(text);
    switch (e.kind()) {
      case ValueTextError::Kind::kOutOfRange:
        if (IsReal(type)) Fail(quoted + " is out of range for a REAL");
        Fail(quoted + " is out of range for " + std::string(ToString(type)) + " (" + e.range() + ")");
      case ValueTextError::Kind::kOddHex:
        Fail(quoted + " is not hex bytes (odd number of digits)");
      case ValueTextError::Kind::kNotHex:
      case ValueTextError::Kind::kSplitByte:
        Fail(quoted + " is not hex bytes");
      case ValueTextError::Kind::kUnsupported:
        Fail("values of data type " + std::string(ToString(type)) + " are not supported");
      default:
        Fail(quoted + " is not a number");
    }
  }
}

}  // namespace

EdsValue ParseEdsValue(DataType type, std::string_view text, bool allow_node_id) {
  if (type == DataType::kVisibleString) return EdsValue{ToBytes(text), false};
  std::string_view value = StripInlineComment(text);
  if (!IsIntegerType(type)) return EdsValue{Encode(type, value), false};

  auto at = FindNodeId(value);
  if (at == std::string_view::npos) return EdsValue{Encode(type, value), false};
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
  return EdsValue{Encode(type, constant), true};
}

std::string FormatEdsValue(DataType type, std::span<const std::uint8_t> bytes, bool adds_node_id) {
  std::string number = FormatValueText(type, bytes, ValueSyntax::kEds);
  if (!adds_node_id || !IsIntegerType(type)) return number;
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
