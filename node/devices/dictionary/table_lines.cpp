#include "node/devices/dictionary/table_lines.hpp"

#include <charconv>
#include <cstdio>
#include <optional>
#include <string>
#include <utility>

#include "node/devices/dictionary/od_table.hpp"

namespace canfleet::devices::od_table {
namespace {

/// One loop variable and its values, already spelled (zero-padded to the width of FIRST).
struct LoopVariable {
  std::string name;
  std::vector<std::string> values;
};

struct Loop {
  std::size_t header_line = 0;
  std::vector<LoopVariable> variables;
  std::vector<TableLine> body;  ///< raw lines, expanded when the loop closes
};

bool IsNameChar(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
}

std::vector<std::string_view> Words(std::string_view text) {
  std::vector<std::string_view> words;
  std::size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && (text[i] == ' ' || text[i] == '\t'))
      ++i;
    std::size_t start = i;
    while (i < text.size() && text[i] != ' ' && text[i] != '\t')
      ++i;
    if (i > start) words.push_back(text.substr(start, i - start));
  }
  return words;
}

std::optional<unsigned> Decimal(std::string_view text) {
  unsigned value = 0;
  auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || text.empty()) return std::nullopt;
  return value;
}

/// "01..12" → "01", "02", … "12".
std::vector<std::string> RangeValues(std::string_view range, std::string_view file, std::size_t line) {
  const auto dots = range.find("..");
  const auto first_text = range.substr(0, dots);
  const auto first = Decimal(first_text);
  const auto last = Decimal(dots == std::string_view::npos ? std::string_view() : range.substr(dots + 2));
  if (!first.has_value() || !last.has_value() || *last < *first || *last - *first >= 1000) {
    throw OdTableError(
        std::string(file), line, "",
        "@for range \"" + std::string(range) + "\" is not FIRST..LAST (decimal, at most 1000 values)");
  }
  const unsigned from = *first;
  const unsigned to = *last;
  std::vector<std::string> values;
  for (unsigned v = from; v <= to; ++v) {
    std::string spelled = std::to_string(v);
    if (spelled.size() < first_text.size()) spelled.insert(0, first_text.size() - spelled.size(), '0');
    values.push_back(std::move(spelled));
  }
  return values;
}

Loop ParseLoopHeader(std::string_view text, std::string_view file, std::size_t line) {
  auto words = Words(text.substr(4));
  if (words.empty() || words.size() % 2 != 0) {
    throw OdTableError(std::string(file), line, "", "@for needs VAR FIRST..LAST pairs");
  }
  Loop loop;
  loop.header_line = line;
  for (std::size_t i = 0; i < words.size(); i += 2) {
    LoopVariable variable{std::string(words[i]), RangeValues(words[i + 1], file, line)};
    for (char c : variable.name) {
      if (!IsNameChar(c))
        throw OdTableError(std::string(file), line, "",
                           "@for variable \"" + variable.name + "\" is not a name");
    }
    if (!loop.variables.empty() && loop.variables.front().values.size() != variable.values.size()) {
      throw OdTableError(std::string(file), line, "",
                         "@for ranges advance together and must have the same length");
    }
    loop.variables.push_back(std::move(variable));
  }
  return loop;
}

std::string Substitute(std::string text, const LoopVariable& variable, const std::string& value) {
  const std::string token = "{" + variable.name + "}";
  for (auto at = text.find(token); at != std::string::npos; at = text.find(token, at + value.size()))
    text.replace(at, token.size(), value);
  return text;
}

void Emit(std::vector<TableLine>& out, TableLine line, std::string_view file) {
  if (out.size() >= kMaxExpandedLines)
    throw OdTableError(std::string(file), line.number, "", "the table expands to too many lines");
  out.push_back(std::move(line));
}

/// Closes the innermost loop: its body, once per value, into the enclosing body (or the output).
void CloseLoop(std::vector<Loop>& open, std::vector<TableLine>& out, std::string_view file) {
  Loop loop = std::move(open.back());
  open.pop_back();
  std::vector<TableLine>& target = open.empty() ? out : open.back().body;
  for (std::size_t k = 0; k < loop.variables.front().values.size(); ++k) {
    for (const TableLine& raw : loop.body) {
      TableLine line = raw;
      for (const LoopVariable& variable : loop.variables)
        line.text = Substitute(std::move(line.text), variable, variable.values[k]);
      Emit(target, std::move(line), file);
    }
  }
}

/// Every line but a comment becomes EDS text, which holds no control character but tab (CiA 306
/// files are lines of text; the EDS writer refuses them, and a table must not give an EDS that
/// cannot be written).
void CheckPrintable(std::string_view line, std::string_view file_name, std::size_t number) {
  for (char c : line) {
    const auto byte = static_cast<unsigned char>(c);
    if ((byte < 0x20 && byte != '\t') || byte == 0x7F) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "%02Xh", byte);
      throw OdTableError(std::string(file_name), number, "",
                         std::string("a control character (") + hex + ") in a line: tables are text");
    }
  }
}

}  // namespace

std::string_view Trim(std::string_view text) {
  auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  while (!text.empty() && blank(text.front()))
    text.remove_prefix(1);
  while (!text.empty() && blank(text.back()))
    text.remove_suffix(1);
  return text;
}

std::vector<TableLine> ExpandLines(std::string_view text, std::string_view file_name) {
  std::vector<TableLine> out;
  std::vector<Loop> open;
  std::size_t number = 0;
  while (!text.empty()) {
    ++number;
    auto newline = text.find('\n');
    std::string_view raw = text.substr(0, newline);
    text.remove_prefix(newline == std::string_view::npos ? text.size() : newline + 1);
    std::string_view line = Trim(raw);
    if (line.empty() || line.front() == '#') continue;
    CheckPrintable(line, file_name, number);
    if (line.starts_with("@for ") || line == "@for") {
      if (open.size() >= 8)
        throw OdTableError(std::string(file_name), number, "", "@for loops nest at most 8 deep");
      open.push_back(ParseLoopHeader(line, file_name, number));
    } else if (line == "@end") {
      if (open.empty()) throw OdTableError(std::string(file_name), number, "", "@end without @for");
      CloseLoop(open, out, file_name);
    } else {
      Emit(open.empty() ? out : open.back().body, TableLine{number, std::string(line)}, file_name);
    }
  }
  if (!open.empty()) {
    throw OdTableError(std::string(file_name), open.back().header_line, "", "@for without @end");
  }
  return out;
}

}  // namespace canfleet::devices::od_table
