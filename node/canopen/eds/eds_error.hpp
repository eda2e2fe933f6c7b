#pragma once
/// @file The one exception of the EDS module: a file that cannot be read (or an object dictionary
/// that cannot be written as CiA 306 text), located by file, line, section and key.

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>

namespace canfleet::canopen {

/// Thrown by ReadEds/ParseEds for any malformed input and by WriteEds for a dictionary that has no
/// CiA 306 spelling. what() reads like a compiler diagnostic:
/// `quad.eds:123: [2090sub1] DefaultValue: "0xZZ" is not a number`.
class EdsError : public std::runtime_error {
 public:
  /// @param file    the file name as given by the caller (may be empty for written output)
  /// @param line    1-based line number; 0 when the problem is not on one line (e.g. file not found)
  /// @param section the section name as spelled in the file, without brackets; empty if none
  /// @param key     the key as spelled in the file; empty if the problem is the section itself
  /// @param detail  what is wrong
  EdsError(std::string file, std::size_t line, std::string section, std::string key, std::string detail);

  const std::string& file() const { return file_; }
  std::size_t line() const { return line_; }
  const std::string& section() const { return section_; }
  const std::string& key() const { return key_; }
  const std::string& detail() const { return detail_; }

 private:
  std::string file_;
  std::size_t line_;
  std::string section_;
  std::string key_;
  std::string detail_;
};

/// Quotes a value for an error message, cutting it short and escaping bytes that are not printable
/// so a message about binary input stays one readable line.
std::string QuoteForError(std::string_view text);

}  // namespace canfleet::canopen
