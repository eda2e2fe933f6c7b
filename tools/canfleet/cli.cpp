#include "tools/canfleet/cli.hpp"

#include <charconv>
#include <iostream>
#include <limits>

#include "orchestrator/control/control_client.hpp"
#include "orchestrator/control/duration_text.hpp"

namespace canfleet::cli {

namespace {

bool IsHexDigit(char c) {
  return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F');
}

/// Digits of `text` in `base` into `value`; false unless all of it is a number that fits.
bool Digits(std::string_view text, int base, std::uint64_t& value) {
  if (text.empty()) return false;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value, base);
  return ec == std::errc() && end == text.data() + text.size();
}

/// "0x1017" or "1017h" -> the hex digits; empty when neither form.
std::string_view HexDigits(std::string_view text) {
  if (text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) return text.substr(2);
  if (text.size() > 1 && (text.back() == 'h' || text.back() == 'H')) return text.substr(0, text.size() - 1);
  return {};
}

std::string Hex(std::uint32_t value) {
  char buffer[16];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, value, 16);
  std::string s(buffer, end);
  for (auto& c : s)
    c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return "0x" + s;
}

std::string HexError(std::string_view text, std::string_view what, std::uint32_t max) {
  const std::string_view digits = HexDigits(text);
  std::uint64_t value = 0;
  if (digits.empty()) {
    bool all_hex = !text.empty();
    for (const char c : text)
      all_hex = all_hex && IsHexDigit(c);
    if (all_hex)
      return std::string(what) + " \"" + std::string(text) + "\" is ambiguous: write it in hex as 0x" +
             std::string(text) + " or " + std::string(text) + "h";
    return std::string(what) + " \"" + std::string(text) + "\" is not a hex number (e.g. 0x1017 or 1017h)";
  }
  if (!Digits(digits, 16, value))
    return std::string(what) + " \"" + std::string(text) + "\" is not a hex number (e.g. 0x1017 or 1017h)";
  if (value > max)
    return std::string(what) + " \"" + std::string(text) + "\" is out of range (0.." + Hex(max) + ")";
  return {};
}

std::string NumberError(std::string_view text, std::string_view what, std::uint32_t max) {
  const std::string_view digits = HexDigits(text);
  std::uint64_t value = 0;
  if (!(digits.empty() ? Digits(text, 10, value) : Digits(digits, 16, value)))
    return std::string(what) + " \"" + std::string(text) + "\" is not a number (decimal, 0x1F or 1Fh)";
  if (value > max)
    return std::string(what) + " \"" + std::string(text) + "\" is out of range (0.." + std::to_string(max) +
           ")";
  return {};
}

}  // namespace

control::Response Call(const GlobalOptions& global, control::Request request) {
  try {
    control::ControlClient client(global.control);
    control::Response response = client.Call(std::move(request), global.timeout);
    if (!response.error().empty()) {
      if (response.bad_request()) throw UsageError(response.error());
      throw CommandError(response.error());
    }
    if (!response.notice().empty()) std::cerr << "canfleet: notice: " << response.notice() << '\n';
    return response;
  } catch (const control::ControlError& e) {
    throw CommandError(e.what());
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());  // a malformed --control
  }
}

void PrintDone(const control::Response& response, const std::string& fallback) {
  const std::string& detail = response.done().detail();
  std::cout << (detail.empty() ? fallback : detail) << '\n';
}

std::uint32_t ParseHex(std::string_view text, std::string_view what, std::uint32_t max) {
  if (const std::string error = HexError(text, what, max); !error.empty()) throw UsageError(error);
  std::uint64_t value = 0;
  Digits(HexDigits(text), 16, value);
  return static_cast<std::uint32_t>(value);
}

std::uint32_t ParseNumber(std::string_view text, std::string_view what, std::uint32_t max) {
  if (const std::string error = NumberError(text, what, max); !error.empty()) throw UsageError(error);
  const std::string_view digits = HexDigits(text);
  std::uint64_t value = 0;
  if (digits.empty())
    Digits(text, 10, value);
  else
    Digits(digits, 16, value);
  return static_cast<std::uint32_t>(value);
}

CLI::Validator HexValidator(std::uint32_t max) {
  return CLI::Validator([max](std::string& s) { return HexError(s, "value", max); }, "HEX");
}

CLI::Validator NumberValidator(std::uint32_t max) {
  return CLI::Validator([max](std::string& s) { return NumberError(s, "value", max); }, "NUMBER");
}

CLI::Validator DurationValidator() {
  return CLI::Validator(
      [](std::string& s) {
        std::string error;
        const auto d = control::ParseDuration(s, &error);
        if (!d) return error;
        if (d->count() > std::numeric_limits<std::uint32_t>::max())
          return "duration \"" + s + "\": longer than 49 days";
        return std::string();
      },
      "DURATION");
}

std::uint32_t DurationMs(const std::string& text) {
  std::string error;
  const auto d = control::ParseDuration(text, &error);
  if (!d) throw UsageError(error);
  if (d->count() > std::numeric_limits<std::uint32_t>::max())
    throw UsageError("duration \"" + text + "\": longer than 49 days");
  return static_cast<std::uint32_t>(d->count());
}

}  // namespace canfleet::cli
