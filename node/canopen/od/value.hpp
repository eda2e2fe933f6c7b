#pragma once
/// @file Little-endian encoding of OD values (CiA 301 §7.1: all numbers travel little-endian).
/// Values are kept as the bytes that go on the wire; these helpers convert at the edges.

#include <bit>
#include <concepts>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "node/canopen/od/types.hpp"

namespace canfleet::canopen {

using Bytes = std::vector<std::uint8_t>;

/// Encodes an integer, bool or floating value in `size` little-endian bytes (default: sizeof(T)).
template <typename T>
requires std::is_arithmetic_v<T> Bytes EncodeLe(T value, std::size_t size = sizeof(T)) {
  std::uint64_t raw = 0;
  if constexpr (std::is_floating_point_v<T>) {
    if constexpr (sizeof(T) == 4)
      raw = std::bit_cast<std::uint32_t>(value);
    else
      raw = std::bit_cast<std::uint64_t>(value);
  } else {
    raw = static_cast<std::uint64_t>(value);
  }
  Bytes out(size);
  for (std::size_t i = 0; i < size; ++i)
    out[i] = static_cast<std::uint8_t>(raw >> (8 * i));
  return out;
}

/// Zero-extended little-endian read of up to 8 bytes.
inline std::uint64_t DecodeUnsignedLe(std::span<const std::uint8_t> bytes) {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < bytes.size() && i < 8; ++i)
    v |= std::uint64_t{bytes[i]} << (8 * i);
  return v;
}

/// Sign-extended little-endian read of 1..8 bytes.
inline std::int64_t DecodeSignedLe(std::span<const std::uint8_t> bytes) {
  std::uint64_t v = DecodeUnsignedLe(bytes);
  std::size_t n = bytes.size() < 8 ? bytes.size() : 8;
  if (n > 0 && n < 8 && (v >> (8 * n - 1)) & 1) v |= ~std::uint64_t{0} << (8 * n);
  return static_cast<std::int64_t>(v);
}

/// Converts a value of `type` held in `bytes` to a double (for limits and scaling).
double DecodeAsDouble(DataType type, std::span<const std::uint8_t> bytes);

/// Three-way comparison of two values of the same numeric type: <0, 0, >0.
int CompareNumeric(DataType type, std::span<const std::uint8_t> a, std::span<const std::uint8_t> b);

/// Human-readable value for logs and CLIs: decimal numbers, quoted strings, hex for domains.
std::string FormatValue(DataType type, std::span<const std::uint8_t> bytes);

inline Bytes ToBytes(std::string_view text) {
  return Bytes(text.begin(), text.end());
}

}  // namespace canfleet::canopen
