#include "node/canopen/eds/ini_section.hpp"

#include <algorithm>

#include "node/canopen/eds/eds_error.hpp"
#include "node/canopen/eds/eds_number.hpp"

namespace canfleet::canopen {

std::string ToLowerAscii(std::string_view text) {
  std::string out(text);
  for (char& c : out) {
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  }
  return out;
}

int CompareNoCase(std::string_view a, std::string_view b) {
  auto lower = [](char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; };
  const std::size_t n = std::min(a.size(), b.size());
  for (std::size_t i = 0; i < n; ++i) {
    char x = lower(a[i]), y = lower(b[i]);
    if (x != y) return static_cast<unsigned char>(x) < static_cast<unsigned char>(y) ? -1 : 1;
  }
  return a.size() < b.size() ? -1 : (a.size() > b.size() ? 1 : 0);
}

SectionReader::SectionReader(const IniSection& section, std::string_view file_name)
    : section_(&section), file_name_(file_name) {
  sorted_.reserve(section.entries.size());
  for (const IniEntry& entry : section.entries)
    sorted_.push_back(&entry);
  std::stable_sort(sorted_.begin(), sorted_.end(),
                   [](const IniEntry* a, const IniEntry* b) { return CompareNoCase(a->key, b->key) < 0; });
}

const IniEntry* SectionReader::Find(std::string_view key) const {
  auto it = std::lower_bound(
      sorted_.begin(), sorted_.end(), key,
      [](const IniEntry* entry, std::string_view k) { return CompareNoCase(entry->key, k) < 0; });
  if (it == sorted_.end() || CompareNoCase((*it)->key, key) != 0) return nullptr;
  if (auto next = it + 1; next != sorted_.end() && CompareNoCase((*next)->key, key) == 0) {
    Fail(*next, (*next)->key, "duplicate key (first on line " + std::to_string((*it)->line) + ")");
  }
  return *it;
}

std::optional<std::string_view> SectionReader::Value(std::string_view key) const {
  const IniEntry* entry = Find(key);
  if (!entry || entry->value.empty()) return std::nullopt;
  return entry->value;
}

std::string_view SectionReader::Required(std::string_view key) const {
  const IniEntry* entry = Find(key);
  if (!entry) Fail(nullptr, key, "missing");
  return entry->value;
}

std::optional<std::uint64_t> SectionReader::Unsigned(std::string_view key, std::uint64_t max) const {
  const IniEntry* entry = Find(key);
  if (!entry) return std::nullopt;
  auto text = StripInlineComment(entry->value);
  if (text.empty()) return std::nullopt;
  auto literal = ParseIntegerLiteral(text);
  if (!literal) Fail(entry, entry->key, QuoteForError(text) + " is not a number");
  auto value = ParseUnsignedLiteral(text, max);
  if (!value)
    Fail(entry, entry->key, QuoteForError(text) + " is out of range (0.." + std::to_string(max) + ")");
  return value;
}

std::optional<bool> SectionReader::Flag(std::string_view key) const {
  auto value = Unsigned(key, 1);
  if (!value) return std::nullopt;
  return *value == 1;
}

void SectionReader::Fail(const IniEntry* entry, std::string_view key, std::string detail) const {
  throw EdsError(std::string(file_name_), entry ? entry->line : section_->line, std::string(section_->name),
                 std::string(key), std::move(detail));
}

void SectionReader::FailSection(std::string detail) const {
  Fail(nullptr, "", std::move(detail));
}

}  // namespace canfleet::canopen
