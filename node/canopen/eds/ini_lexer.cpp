#include "node/canopen/eds/ini_lexer.hpp"

#include <cstdio>
#include <string>

#include "node/canopen/eds/eds_error.hpp"

namespace canfleet::canopen {
namespace {

bool IsBlank(char c) {
  return c == ' ' || c == '\t';
}

/// Bytes an EDS line never holds: CiA 306 files are text. Bytes >= 0x80 are allowed (names in
/// Latin-1 or UTF-8 occur in vendor files). A carriage return only ends a line (CRLF); inside one
/// it could not be written back.
bool IsBinary(unsigned char c) {
  return (c < 0x20 && c != '\t') || c == 0x7F;
}

[[noreturn]] void Fail(std::string_view file_name, std::size_t line, std::string detail) {
  throw EdsError(std::string(file_name), line, "", "", std::move(detail));
}

}  // namespace

std::string_view TrimBlanks(std::string_view text) {
  while (!text.empty() && IsBlank(text.front()))
    text.remove_prefix(1);
  while (!text.empty() && IsBlank(text.back()))
    text.remove_suffix(1);
  return text;
}

std::vector<IniSection> LexIni(std::string_view text, std::string_view file_name) {
  constexpr std::string_view kBom = "\xEF\xBB\xBF";
  if (text.starts_with(kBom)) text.remove_prefix(kBom.size());

  std::vector<IniSection> sections;
  std::size_t line_number = 0;
  while (!text.empty()) {
    ++line_number;
    auto end = text.find('\n');
    std::string_view line = text.substr(0, end);
    text.remove_prefix(end == std::string_view::npos ? text.size() : end + 1);
    // CRLF, and the CRCRLF of a CRLF file converted once more.
    while (!line.empty() && line.back() == '\r')
      line.remove_suffix(1);

    for (char c : line) {
      auto byte = static_cast<unsigned char>(c);
      if (IsBinary(byte)) {
        char buf[48];
        if (byte == '\r') Fail(file_name, line_number, "carriage return inside a line");
        std::snprintf(buf, sizeof buf, "binary data (byte 0x%02X): not an EDS text file", byte);
        Fail(file_name, line_number, buf);
      }
    }
    line = TrimBlanks(line);
    if (line.empty() || line.front() == ';' || line.front() == '#') continue;

    if (line.front() == '[') {
      auto close = line.find(']');
      if (close == std::string_view::npos) Fail(file_name, line_number, "section header without ']'");
      auto rest = TrimBlanks(line.substr(close + 1));
      if (!rest.empty() && rest.front() != ';') {
        Fail(file_name, line_number, "unexpected text after section header: " + QuoteForError(rest));
      }
      auto name = TrimBlanks(line.substr(1, close - 1));
      if (name.empty()) Fail(file_name, line_number, "empty section name");
      sections.push_back(IniSection{name, line_number, {}});
      continue;
    }

    auto equals = line.find('=');
    if (equals == std::string_view::npos) {
      Fail(file_name, line_number, "expected [section] or key=value, found " + QuoteForError(line));
    }
    auto key = TrimBlanks(line.substr(0, equals));
    if (key.empty()) Fail(file_name, line_number, "empty key before '='");
    if (sections.empty()) {
      Fail(file_name, line_number, "key " + QuoteForError(key) + " before the first [section]");
    }
    sections.back().entries.push_back(IniEntry{key, TrimBlanks(line.substr(equals + 1)), line_number});
  }
  return sections;
}

}  // namespace canfleet::canopen
