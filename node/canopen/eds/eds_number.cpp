#include "node/canopen/eds/eds_number.hpp"

#include <limits>

#include "node/canopen/eds/ini_lexer.hpp"

namespace canfleet::canopen {
namespace {

int DigitValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return 99;
}

}  // namespace

std::optional<IntegerLiteral> ParseIntegerLiteral(std::string_view text) {
  IntegerLiteral out;
  if (!text.empty() && (text.front() == '+' || text.front() == '-')) {
    out.negative = text.front() == '-';
    text.remove_prefix(1);
  }
  unsigned base = 10;
  if (text.size() >= 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) {
    base = 16;
    out.hex = true;
    text.remove_prefix(2);
  } else if (text.size() >= 2 && text[0] == '0') {
    base = 8;
    text.remove_prefix(1);
  }
  if (text.empty()) return std::nullopt;
  constexpr auto kMax = std::numeric_limits<std::uint64_t>::max();
  for (char c : text) {
    auto digit = static_cast<unsigned>(DigitValue(c));
    if (digit >= base) return std::nullopt;
    if (out.magnitude > (kMax - digit) / base) return std::nullopt;
    out.magnitude = out.magnitude * base + digit;
  }
  return out;
}

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
