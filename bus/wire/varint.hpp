#pragma once
/// @file Base-128 varints as protobuf writes them (little-endian groups of 7 bits, high bit =
/// more follows), for the framing and the hand-encoded hot-path messages.

#include <cstddef>
#include <cstdint>
#include <span>

namespace canfleet::wire {

/// Bytes a varint of `value` takes (1..10).
constexpr std::size_t VarintSize(std::uint64_t value) {
  std::size_t n = 1;
  while (value >= 0x80) {
    value >>= 7;
    ++n;
  }
  return n;
}

/// Writes `value` at `out`; returns the byte after it.
inline std::uint8_t* WriteVarint(std::uint64_t value, std::uint8_t* out) {
  while (value >= 0x80) {
    *out++ = static_cast<std::uint8_t>(value | 0x80);
    value >>= 7;
  }
  *out++ = static_cast<std::uint8_t>(value);
  return out;
}

enum class VarintStatus : std::uint8_t { kOk, kIncomplete, kOverlong };

/// Reads a varint from the start of `in`. kIncomplete: `in` ends inside it. kOverlong: more than
/// 10 bytes, or a value beyond 64 bits. On kOk, `value` and `length` (bytes read) are set.
inline VarintStatus ReadVarint(std::span<const std::uint8_t> in, std::uint64_t& value, std::size_t& length) {
  std::uint64_t result = 0;
  for (std::size_t i = 0; i < in.size(); ++i) {
    if (i == 10) return VarintStatus::kOverlong;
    const std::uint64_t group = in[i] & 0x7Fu;
    if (i == 9 && group > 1) return VarintStatus::kOverlong;
    result |= group << (7 * i);
    if ((in[i] & 0x80u) == 0) {
      value = result;
      length = i + 1;
      return VarintStatus::kOk;
    }
  }
  return in.size() >= 10 ? VarintStatus::kOverlong : VarintStatus::kIncomplete;
}

}  // namespace canfleet::wire
