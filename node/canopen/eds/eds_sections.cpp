#include "node/canopen/eds/eds_sections.hpp"

#include <optional>
#include <string>

#include "node/canopen/eds/eds_error.hpp"
#include "node/canopen/eds/ini_section.hpp"

namespace canfleet::canopen {
namespace {

bool IsHexDigit(char c) {
  return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f');
}

/// Parses lower-case hex digits; nullopt if empty, not hex, or above `max`.
std::optional<std::uint32_t> ParseHex(std::string_view digits, std::uint32_t max) {
  if (digits.empty()) return std::nullopt;
  std::uint32_t value = 0;
  for (char c : digits) {
    if (!IsHexDigit(c)) return std::nullopt;
    value = value * 16 + static_cast<std::uint32_t>(c <= '9' ? c - '0' : c - 'a' + 10);
    if (value > max) return std::nullopt;
  }
  return value;
}

class Classifier {
 public:
  Classifier(std::string_view file_name, EdsSections& out) : file_name_(file_name), out_(out) {}

  void Add(const IniSection& section) {
    const std::string lower = ToLowerAscii(section.name);
    if (lower == "fileinfo") return Single(section, out_.file_info);
    if (lower == "deviceinfo") return Single(section, out_.device_info);
    if (lower == "dummyusage") return Single(section, out_.dummy_usage);
    if (lower == "comments") return Single(section, out_.comments);
    // CiA 306 spells it "DeviceComissioning"; tools that fix the spelling are read too.
    if (lower == "devicecomissioning" || lower == "devicecommissioning")
      return Single(section, out_.commissioning);
    if (lower == "mandatoryobjects") return Single(section, out_.object_lists[0]);
    if (lower == "optionalobjects") return Single(section, out_.object_lists[1]);
    if (lower == "manufacturerobjects") return Single(section, out_.object_lists[2]);
    AddObjectSection(section, lower);
  }

 private:
  void AddObjectSection(const IniSection& section, const std::string& lower) {
    std::size_t digits = 0;
    while (digits < lower.size() && IsHexDigit(lower[digits]))
      ++digits;
    if (digits == 0 || digits > 4) return;  // not an object section: ignored
    auto index = static_cast<std::uint16_t>(*ParseHex(std::string_view(lower).substr(0, digits), 0xFFFF));
    std::string_view rest = std::string_view(lower).substr(digits);
    if (rest.empty()) {
      if (auto [it, inserted] = object_index_.emplace(index, &section); !inserted)
        Duplicate(section, *it->second);
      out_.objects.emplace_back(index, &section);
    } else if (rest.starts_with("sub")) {
      auto sub = ParseHex(rest.substr(3), 0xFF);
      if (!sub)
        Fail(section,
             "sub-index " + QuoteForError(section.name.substr(digits + 3)) + " is not a hex byte (0..FF)");
      Keyed(section, out_.subs,
            std::pair<std::uint16_t, std::uint8_t>{index, static_cast<std::uint8_t>(*sub)});
    } else if (rest == "name") {
      Keyed(section, out_.names, index);
    } else if (rest == "value") {
      Keyed(section, out_.values, index);
    }
    // Anything else ([1018ObjectLinks], tool sections): ignored.
  }

  template <typename Map, typename Key>
  void Keyed(const IniSection& section, Map& map, const Key& key) {
    if (auto [it, inserted] = map.emplace(key, &section); !inserted) Duplicate(section, *it->second);
  }

  void Single(const IniSection& section, const IniSection*& slot) {
    if (slot) Duplicate(section, *slot);
    slot = &section;
  }

  [[noreturn]] void Duplicate(const IniSection& section, const IniSection& first) {
    Fail(section, "duplicate section (first on line " + std::to_string(first.line) + ")");
  }

  [[noreturn]] void Fail(const IniSection& section, std::string detail) {
    throw EdsError(std::string(file_name_), section.line, std::string(section.name), "", std::move(detail));
  }

  std::string_view file_name_;
  EdsSections& out_;
  std::map<std::uint16_t, const IniSection*> object_index_;
};

}  // namespace

EdsSections ClassifySections(const std::vector<IniSection>& sections, std::string_view file_name) {
  EdsSections out;
  Classifier classifier(file_name, out);
  for (const IniSection& section : sections)
    classifier.Add(section);
  return out;
}

}  // namespace canfleet::canopen
