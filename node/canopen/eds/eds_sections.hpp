#pragma once
/// @file Sorts a lexed EDS/DCF into the sections CiA 306 defines (internal to the reader).
/// Section names are matched without regard to case; object sections are "[1018]" (index in hex),
/// "[1018sub2]" (sub-index in hex), "[1003Name]" and "[1003Value]" (CompactSubObj names/values).

#include <array>
#include <cstdint>
#include <map>
#include <string_view>
#include <utility>
#include <vector>

#include "node/canopen/eds/ini_lexer.hpp"

namespace canfleet::canopen {

struct EdsSections {
  const IniSection* file_info = nullptr;
  const IniSection* device_info = nullptr;
  const IniSection* dummy_usage = nullptr;
  const IniSection* comments = nullptr;
  const IniSection* commissioning = nullptr;        ///< [DeviceComissioning] (DCF)
  std::array<const IniSection*, 3> object_lists{};  ///< Mandatory, Optional, ManufacturerObjects
  std::vector<std::pair<std::uint16_t, const IniSection*>> objects;  ///< in file order
  std::map<std::pair<std::uint16_t, std::uint8_t>, const IniSection*> subs;
  std::map<std::uint16_t, const IniSection*> names;
  std::map<std::uint16_t, const IniSection*> values;
};

/// Classifies `sections` (which must outlive the result). Unknown sections are skipped. Throws
/// EdsError for a known section given twice and for a sub-index that is not a hex byte.
EdsSections ClassifySections(const std::vector<IniSection>& sections, std::string_view file_name);

}  // namespace canfleet::canopen
