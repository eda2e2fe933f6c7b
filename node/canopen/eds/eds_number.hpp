#pragma once
/// @file Integer literals as EDS files write them (CiA 306 §4.2, entry value interpretation):
/// `0x` hexadecimal, a leading 0 for octal, otherwise decimal, with an optional sign.

#include <cstdint>
#include <optional>
#include <string_view>

#include "node/canopen/od/value_text.hpp"

namespace canfleet::canopen {

/// Parses the whole of `text` (no blanks inside) as an integer literal; nullopt if it is not
/// one or does not fit 64 bits. The grammar is the value codec's (ValueSyntax::kEds).
inline std::optional<IntegerLiteral> ParseIntegerLiteral(std::string_view text) {
  return ReadIntegerLiteral(text, ValueSyntax::kEds);
}

/// A non-negative literal no greater than `max`, or nullopt.
std::optional<std::uint64_t> ParseUnsignedLiteral(std::string_view text, std::uint64_t max);

/// Cuts a trailing `; comment` off a value and trims it. CiA 306 only knows whole-line comments,
/// but vendor files put comments behind numbers, so numeric keys tolerate them. Text values
/// (names, VISIBLE_STRING defaults) are taken as written and keep their ';'.
std::string_view StripInlineComment(std::string_view value);

}  // namespace canfleet::canopen
