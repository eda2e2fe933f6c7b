#include "orchestrator/control/duration_text.hpp"

#include <array>
#include <cstdint>
#include <limits>

namespace canfleet::control {

namespace {

struct Unit {
  std::string_view suffix;
  std::int64_t ms;
};

// "ms" before "m" and "s": the longest suffix wins.
constexpr std::array<Unit, 4> kUnits{{{"ms", 1}, {"s", 1'000}, {"m", 60'000}, {"h", 3'600'000}}};

bool IsDigit(char c) {
  return c >= '0' && c <= '9';
}

std::optional<std::chrono::milliseconds> Fail(std::string_view text, std::string_view why,
                                              std::string* error) {
  if (error != nullptr) *error = "duration \"" + std::string(text) + "\": " + std::string(why);
  return std::nullopt;
}

}  // namespace

std::optional<std::chrono::milliseconds> ParseDuration(std::string_view text, std::string* error) {
  std::size_t i = 0;
  if (!text.empty() && text[0] == '-') return Fail(text, "must not be negative", error);
  std::string_view whole;
  std::string_view fraction;
  while (i < text.size() && IsDigit(text[i]))
    ++i;
  whole = text.substr(0, i);
  if (i < text.size() && text[i] == '.') {
    const std::size_t start = ++i;
    while (i < text.size() && IsDigit(text[i]))
      ++i;
    fraction = text.substr(start, i - start);
    if (fraction.empty()) return Fail(text, "expected digits after '.'", error);
  }
  if (whole.empty() && fraction.empty())
    return Fail(text, "expected a number and a unit (e.g. 500ms, 2s, 1.5s, 1m)", error);
  const std::string_view suffix = text.substr(i);
  if (suffix.empty()) return Fail(text, "missing unit (e.g. 500ms, 2s, 1.5s, 1m)", error);
  const Unit* unit = nullptr;
  for (const Unit& u : kUnits)
    if (suffix == u.suffix) unit = &u;
  if (unit == nullptr)
    return Fail(text, "unknown unit \"" + std::string(suffix) + "\" (ms, s, m or h)", error);

  // Exact arithmetic: whole * unit + fraction * unit / 10^digits, which must be whole ms.
  constexpr std::int64_t kMax = std::numeric_limits<std::int64_t>::max() / 10;
  std::int64_t ms = 0;
  for (const char c : whole) {
    if (ms > kMax / unit->ms) return Fail(text, "too long", error);
    ms = ms * 10 + (c - '0');
  }
  if (ms > kMax / unit->ms) return Fail(text, "too long", error);
  ms *= unit->ms;
  // The fraction's digits beyond 7 can only matter if they are not zero (1 h = 3.6e6 ms).
  std::int64_t numerator = 0;
  std::int64_t denominator = 1;
  for (const char c : fraction) {
    if (denominator >= 10'000'000) {
      if (c != '0') return Fail(text, "finer than 1 ms", error);
      continue;
    }
    numerator = numerator * 10 + (c - '0');
    denominator *= 10;
  }
  const std::int64_t scaled = numerator * unit->ms;
  if (scaled % denominator != 0) return Fail(text, "finer than 1 ms", error);
  ms += scaled / denominator;
  return std::chrono::milliseconds(ms);
}

std::string FormatDuration(std::chrono::milliseconds d) {
  std::int64_t ms = d.count();
  std::string sign;
  if (ms < 0) {
    sign = "-";
    ms = -ms;
  }
  if (ms != 0 && ms % 3'600'000 == 0) return sign + std::to_string(ms / 3'600'000) + "h";
  if (ms != 0 && ms % 60'000 == 0) return sign + std::to_string(ms / 60'000) + "m";
  if (ms < 1'000) return sign + std::to_string(ms) + "ms";
  std::string text = sign + std::to_string(ms / 1'000);
  if (const std::int64_t rest = ms % 1'000; rest != 0) {
    std::string digits = std::to_string(rest);
    digits.insert(0, 3 - digits.size(), '0');
    while (digits.back() == '0')
      digits.pop_back();
    text += "." + digits;
  }
  return text + "s";
}

}  // namespace canfleet::control
