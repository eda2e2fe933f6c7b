#pragma once
/// @file Reads the file-level sections of an EDS/DCF (internal to the reader): [FileInfo],
/// [DeviceInfo], [DummyUsage], [Comments] and the DCF's [DeviceComissioning].

#include <string_view>

#include "node/canopen/eds/eds_file.hpp"
#include "node/canopen/eds/eds_sections.hpp"

namespace canfleet::canopen {

/// Fills everything in `out` but the object dictionary. Throws EdsError for an invalid value of a
/// known key; unknown keys are ignored.
void ReadFileLevelSections(const EdsSections& sections, std::string_view file_name, EdsFile& out);

/// CiA 306 §4.3: a time is hh:mm(AM|PM) (24-hour times without AM/PM, and a blank before AM/PM,
/// are accepted as vendor files use them). What the reader accepts for CreationTime and
/// ModificationTime, and what the dictionary tables check their @creation_time against.
bool IsEdsTime(std::string_view text);
/// CiA 306 §4.3: a date is mm-dd-yyyy (CreationDate, ModificationDate).
bool IsEdsDate(std::string_view text);

/// The baud rates CiA 306 §4.4 lists as DeviceInfo BaudRate_<kbit/s> keys.
inline constexpr std::uint16_t kEdsBaudRatesKbit[] = {10, 20, 50, 125, 250, 500, 800, 1000};

}  // namespace canfleet::canopen
