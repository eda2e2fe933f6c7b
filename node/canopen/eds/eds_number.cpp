#include "node/canopen/eds/eds_number.hpp"

#include "node/canopen/eds/ini_lexer.hpp"

namespace canfleet::canopen {

std::optional<std::uint64_t> ParseUnsignedLiteral(std::string_view text, std::uint64_t max) {
  auto literal = ParseIntegerLiteral(text);
  if (!literal || (literal->negative && literal->magnitude != 0) || literal->magnitude > max)
    return std::nullopt;
  return literal->magnitude;
}

std::string_view StripInlineComment(std::string_view value) {
  auto semicolon = value.find(';');
  if (semicolon != std::string_view::npos) value = value.substr(0, semicolon);
  return TrimBlanks(value);
}

}  // namespace canfleet::canopen
