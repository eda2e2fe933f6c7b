#pragma once
/// @file Splits EDS/DCF text into sections and key=value entries (CiA 306 §4.1: an INI-style text
/// file of [sections] holding key=value lines; a line starting with ';' is a comment). The lexer
/// knows nothing about CANopen; ini_section.hpp and the readers interpret what it finds.

#include <cstddef>
#include <string_view>
#include <vector>

namespace canfleet::canopen {

/// One `key=value` line. Both views point into the lexed text and are trimmed of spaces and tabs.
struct IniEntry {
  std::string_view key;
  std::string_view value;
  std::size_t line = 0;  ///< 1-based
};

/// One `[name]` section and the entries up to the next section.
struct IniSection {
  std::string_view name;  ///< as spelled, trimmed, without brackets
  std::size_t line = 0;   ///< line of the `[name]` header
  std::vector<IniEntry> entries;
};

/// Lexes `text`. The result holds views into `text`, which must outlive it.
/// Accepts LF and CRLF line ends, a UTF-8 byte order mark, blank lines and comment lines
/// (';' or '#' first after leading blanks). Throws EdsError (naming `file_name` and the line) for
/// control characters other than tab (binary input; a CR only right before the LF), an entry
/// before the first section, a line that is neither a section header nor `key=value`, and an
/// empty key or section name.
std::vector<IniSection> LexIni(std::string_view text, std::string_view file_name);

/// Removes leading and trailing spaces and tabs.
std::string_view TrimBlanks(std::string_view text);

}  // namespace canfleet::canopen
