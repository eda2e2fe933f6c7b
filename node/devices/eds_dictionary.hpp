#pragma once
/// @file Object dictionaries from EDS files (CiA 306), for variants and for the generic node. A
/// variant's EDS is compiled into the binary, deflated (canfleet_device_dictionary() in
/// CMakeLists.txt, embedded_eds.hpp), so the node runs from any directory; `canfleet-node
/// --write-eds` writes the same text for users' masters.

#include <filesystem>
#include <string_view>

#include "node/canopen/od/object_dictionary.hpp"
#include "node/devices/embedded_eds.hpp"

namespace canfleet::devices {

/// The dictionary described by an EDS compiled into the binary. From the second request for the
/// same EDS on, the parsed dictionary is kept; every call returns a fresh copy (a node's dictionary
/// is its own).
/// @param file_name for error messages
/// @throws canopen::EdsError
canopen::ObjectDictionary DictionaryFromEmbeddedEds(const EmbeddedEds& eds, std::string_view file_name);

/// The dictionary of an EDS or DCF file.
/// @throws canopen::EdsError naming the file, line, section and key
canopen::ObjectDictionary DictionaryFromEdsFile(const std::filesystem::path& path);

/// A variant's EDS: the compiled-in one, unless the user named another file.
canopen::ObjectDictionary LoadVariantDictionary(const EmbeddedEds& eds, std::string_view file_name,
                                                const std::filesystem::path& override_path);

}  // namespace canfleet::devices
