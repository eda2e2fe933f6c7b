#pragma once
/// @file A variant's EDS as the build compiles it into the binary: deflated (zlib). A device's EDS
/// is 60-380 kB of text that a node reads once, at start-up; kept as text in .rodata, all of it
/// (0.85 MB for the five variants) stayed among the binary's resident pages for the life of every
/// node process. Deflated it is a tenth of that, and the text lives on the heap only while it is
/// parsed (bench/idle/README.md).

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

namespace canfleet::devices {

struct EmbeddedEds {
  std::span<const std::uint8_t> deflated;  ///< zlib stream (RFC 1950), static storage
  std::size_t size = 0;                    ///< bytes of the inflated text

  /// The EDS text.
  /// @throws std::runtime_error if the stream does not inflate to `size` bytes (a build error)
  std::string Text() const;
};

}  // namespace canfleet::devices
