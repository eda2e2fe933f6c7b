#pragma once
/// @file Appending little-endian integers to a byte buffer: the stored files' encoders
/// (store_file.cpp, store_transaction.cpp) write their headers and entries with these.

#include <cstddef>
#include <cstdint>

#include "node/canopen/od/value.hpp"

namespace canfleet::canopen::le {

inline void Put8(Bytes& out, std::uint8_t v) {
  out.push_back(v);
}
inline void Put16(Bytes& out, std::uint16_t v) {
  out.push_back(static_cast<std::uint8_t>(v));
  out.push_back(static_cast<std::uint8_t>(v >> 8));
}
inline void Put32(Bytes& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i)
    out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}
/// Overwrites the four bytes at `at` (a length or CRC known only once the rest is written).
inline void Patch32(Bytes& out, std::size_t at, std::uint32_t v) {
  for (std::size_t i = 0; i < 4; ++i)
    out[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}

}  // namespace canfleet::canopen::le
