#pragma once
/// @file The first pass over a dictionary table: its lines, with every `@for` … `@end` loop
/// expanded (FORMAT.md), each line keeping the number it has in the file for error messages.

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace canfleet::devices::od_table {

struct TableLine {
  std::size_t number = 0;  ///< 1-based, as written in the file
  std::string text;        ///< trimmed, loop variables substituted
};

/// The table's meaningful lines (no blank or `#` comment lines, no `@for`/`@end`), loops expanded.
/// @throws OdTableError for an unbalanced loop, a bad range or a loop that would expand past
///         kMaxExpandedLines (a fuzzed file must not exhaust memory)
std::vector<TableLine> ExpandLines(std::string_view text, std::string_view file_name);

/// Seven times the largest product's table (the valve controller's expands to fewer lines than its
/// 2740 EDS sections): room for any device, and a bound on the work a malformed file can cause
/// (at 200 000, one fuzzed input of nested loops took 6.5 s to expand, write and read back).
inline constexpr std::size_t kMaxExpandedLines = 20000;

/// `text` without leading and trailing blanks (spaces, tabs, CR).
std::string_view Trim(std::string_view text);

}  // namespace canfleet::devices::od_table
