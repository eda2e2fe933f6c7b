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

/// The baud rates CiA 306 §4.4 lists as DeviceInfo BaudRate_<kbit/s> keys.
inline constexpr std::uint16_t kEdsBaudRatesKbit[] = {10, 20, 50, 125, 250, 500, 800, 1000};

}  // namespace canfleet::canopen
