#pragma once
/// @file CRC-16-CCITT of SDO block transfers (CiA 301 v4.2 §7.2.4.3.16): polynomial 1021h
/// (x^16 + x^12 + x^5 + 1), initial value 0000h, MSB first, no reflection, no final XOR — the
/// "XMODEM" variant, as in CANopenNode `301/crc16-ccitt.c` and Lely `src/co/crc.c`.
/// Check value: "123456789" → 31C3h.

#include <cstdint>
#include <span>

namespace canfleet::canopen {

/// Continues a CRC over `data`; pass the previous result as `crc` to checksum data in pieces
/// (a block transfer starts with 0).
std::uint16_t Crc16Ccitt(std::span<const std::uint8_t> data, std::uint16_t crc = 0);

}  // namespace canfleet::canopen
