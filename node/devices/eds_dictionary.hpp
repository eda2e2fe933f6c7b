#pragma once
/// @file Object dictionaries from EDS files (CiA 306), for variants and for the generic node. A
/// variant's EDS is compiled into the binary (canfleet_device_eds() in CMakeLists.txt) so the node
/// runs from any directory; the same file ships in the variant's folder for users' masters.

#include <filesystem>
#include <string_view>

#include "node/canopen/od/object_dictionary.hpp"

namespace canfleet::devices {

/// The dictionary described by EDS text compiled into the binary. The text is parsed once per
/// process; every call returns a fresh copy (a node's dictionary is its own).
/// @param file_name for error messages
/// @throws canopen::EdsError
canopen::ObjectDictionary DictionaryFromEdsText(std::string_view text, std::string_view file_name);

/// The dictionary of an EDS or DCF file.
/// @throws canopen::EdsError naming the file, line, section and key
canopen::ObjectDictionary DictionaryFromEdsFile(const std::filesystem::path& path);

/// A variant's EDS: the compiled-in text, unless the user named another file.
canopen::ObjectDictionary LoadVariantDictionary(std::string_view text, std::string_view file_name,
                                                const std::filesystem::path& override_path);

}  // namespace canfleet::devices
