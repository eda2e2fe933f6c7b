#pragma once
/// @file Dictionary tables (FORMAT.md): a variant's object dictionary as one reviewable table, one
/// row per object or per run of similar sub-objects, each citing its manual section. The build turns
/// a table into the variant's EDS (canfleet-odgen), so the EDS stays the one file users and our
/// node load, while people review and edit the table.

#include <cstddef>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

#include "node/canopen/eds/eds_file.hpp"

namespace canfleet::devices {

/// A table that cannot be read. what() reads like a compiler diagnostic:
/// `valve.od:120: column "default": "0x1G" is not a number`.
class OdTableError : public std::runtime_error {
 public:
  /// @param line   1-based line of the table (of the row as written, inside an @for loop too)
  /// @param column the column's name ("default"), or empty when the line itself is wrong
  OdTableError(std::string file, std::size_t line, std::string column, std::string detail);

  const std::string& file() const { return file_; }
  std::size_t line() const { return line_; }
  const std::string& column() const { return column_; }
  const std::string& detail() const { return detail_; }

 private:
  std::string file_;
  std::size_t line_;
  std::string column_;
  std::string detail_;
};

/// Parses a dictionary table into the EDS it describes (file facts, objects, defaults, limits).
/// @param file_name for error messages
/// @throws OdTableError for any malformed input; never crashes on bad text (fuzzed)
canopen::EdsFile ParseOdTable(std::string_view text, std::string_view file_name);

/// Reads and parses a table file.
/// @throws OdTableError naming the file (line 0 when it cannot be read)
canopen::EdsFile ReadOdTable(const std::filesystem::path& path);

}  // namespace canfleet::devices
