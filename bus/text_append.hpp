#pragma once
/// @file Allocation-light text builders for frame formats (candump log, socketcand): append fixed
/// width upper-case hex and zero-padded decimals to a reused string, without printf.

#include <cstdint>
#include <string>

namespace canfleet {

inline constexpr char kHexDigits[] = "0123456789ABCDEF";

/// Appends the low `digits` nibbles of `value`, most significant first.
inline void AppendHex(std::string& out, std::uint32_t value, int digits) {
  for (int shift = (digits - 1) * 4; shift >= 0; shift -= 4)
    out += kHexDigits[(value >> shift) & 0xF];
}

/// Appends `value` in decimal, zero-padded to at least `min_digits`.
inline void AppendDecimal(std::string& out, std::uint64_t value, int min_digits) {
  char digits[20];
  int n = 0;
  do {
    digits[n++] = static_cast<char>('0' + value % 10);
    value /= 10;
  } while (value != 0);
  for (int i = n; i < min_digits; ++i)
    out += '0';
  while (n > 0)
    out += digits[--n];
}

}  // namespace canfleet
