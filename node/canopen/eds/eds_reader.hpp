#pragma once
/// @file Reading CiA 306 v1.3 EDS and DCF files into an EdsFile (file-level information plus the
/// object dictionary).

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string_view>

#include "node/canopen/eds/eds_error.hpp"
#include "node/canopen/eds/eds_file.hpp"

namespace canfleet::canopen {

/// Files larger than this are refused by ReadEds (real EDS files are well below 1 MiB).
inline constexpr std::uintmax_t kMaxEdsFileBytes = std::uintmax_t{64} << 20;

/// An upper bound on the memory the dictionary of one file may take, so that a small file cannot
/// ask for gigabytes through CompactSubObj expansion (254 copies of one object section). A large
/// real device takes a few MB; 64 MiB is over 100 000 sub-objects.
inline constexpr std::size_t kMaxDictionaryBytes = std::size_t{64} << 20;

/// Reads and parses an EDS or DCF file.
/// @throws EdsError if the file cannot be read or is not a valid EDS/DCF; the message names the
///         file, the line, the section and the key.
EdsFile ReadEds(const std::filesystem::path& path);

/// Parses EDS/DCF text. Any input gives an EdsFile or an EdsError: never a crash, a hang or
/// unbounded memory (the dictionary is capped at kMaxDictionaryBytes).
/// @param file_name used in error messages only
/// @throws EdsError
EdsFile ParseEds(std::string_view text, std::string_view file_name);

}  // namespace canfleet::canopen
