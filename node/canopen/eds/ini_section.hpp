#pragma once
/// @file Case-insensitive key lookup in one lexed section (CiA 306 §4.1: section names and keys
/// are not case-sensitive), with typed getters whose errors name the file, line, section and key.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "node/canopen/eds/ini_lexer.hpp"

namespace canfleet::canopen {

/// ASCII lower case copy (EDS keys and section names are ASCII).
std::string ToLowerAscii(std::string_view text);
/// Case-insensitive (ASCII) three-way comparison.
int CompareNoCase(std::string_view a, std::string_view b);

/// Read access to one section. Unknown keys are never looked at, so they are ignored; a key that
/// is looked up and appears twice is an error, since the file is ambiguous.
class SectionReader {
 public:
  /// Keeps references to `section` and `file_name`; both must outlive the reader.
  SectionReader(const IniSection& section, std::string_view file_name);

  std::string_view name() const { return section_->name; }
  std::size_t line() const { return section_->line; }
  const IniSection& section() const { return *section_; }

  /// The entry for `key` (any case), or nullptr. Throws EdsError if the key appears twice.
  const IniEntry* Find(std::string_view key) const;
  /// The entry's value, or nullopt when the key is absent or its value is empty.
  std::optional<std::string_view> Value(std::string_view key) const;
  /// Like Value, but a missing key is an error (reported at the section header).
  std::string_view Required(std::string_view key) const;

  /// A non-negative integer no greater than `max` (comment after ';' ignored), or nullopt when
  /// absent/empty. Throws EdsError for anything else.
  std::optional<std::uint64_t> Unsigned(std::string_view key, std::uint64_t max) const;
  /// 0 or 1, or nullopt when absent/empty.
  std::optional<bool> Flag(std::string_view key) const;

  /// Throws EdsError located at `entry` (or the section header when null).
  [[noreturn]] void Fail(const IniEntry* entry, std::string_view key, std::string detail) const;
  /// Throws EdsError about the section itself, at its header.
  [[noreturn]] void FailSection(std::string detail) const;

 private:
  const IniSection* section_;
  std::string_view file_name_;
  /// The entries sorted by key without regard to case; equal keys stay in file order.
  std::vector<const IniEntry*> sorted_;
};

}  // namespace canfleet::canopen
