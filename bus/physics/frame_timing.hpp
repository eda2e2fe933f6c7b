#pragma once
/// @file Exact length on the wire of a classical CAN frame (ISO 11898-1 §10.4): the frame's real
/// bits, the stuff bits the transmitter inserts between SOF and the end of the CRC sequence, and
/// the fixed-form tail. Arbitration and bus load in the broker are computed from this.

#include <chrono>
#include <cstdint>

#include "bus/can_frame.hpp"

namespace canfleet {

/// Bits after the CRC sequence that are never stuffed: CRC delimiter 1, ACK slot 1,
/// ACK delimiter 1, end of frame 7.
inline constexpr std::uint32_t kFrameTailBits = 10;
/// Interframe space (intermission) before the next frame may start. Counted in every frame's
/// length so that back-to-back frames tile the bus time line (the convention of bus-load tools).
inline constexpr std::uint32_t kIntermissionBits = 3;

struct FrameBits {
  std::uint32_t unstuffed = 0;  ///< SOF .. end of CRC sequence, before stuffing
  std::uint32_t stuff = 0;      ///< stuff bits inserted into that region
  /// Everything the frame occupies on the bus: stuffed region + tail + intermission.
  std::uint32_t total() const { return unstuffed + stuff + kFrameTailBits + kIntermissionBits; }
};

/// The CAN CRC-15 (polynomial 0x4599, initial 0) over SOF .. last data bit, as transmitted.
std::uint16_t CanCrc15(const CanFrame& frame);

/// Counts the real bits and stuff bits of `frame` (data, remote, 11- or 29-bit).
/// An 8-byte 11-bit data frame is 111 bits unstuffed (98 + 10 + 3) and at most 135 with stuffing.
FrameBits CountFrameBits(const CanFrame& frame);

/// Upper bound of a frame's length for a DLC, 11- or 29-bit (worst-case stuffing).
std::uint32_t MaxFrameBits(std::uint8_t dlc, bool extended, bool remote = false);

/// Duration of `bits` bit times at `bitrate` bit/s.
inline std::chrono::nanoseconds BitTime(std::uint64_t bits, std::uint32_t bitrate) {
  return std::chrono::nanoseconds(bits * 1'000'000'000ULL / bitrate);
}

/// Bus-off recovery needs 128 occurrences of 11 consecutive recessive bits (ISO 11898-1 §12.1.4.2).
inline constexpr std::uint32_t kBusOffRecoveryBits = 128 * 11;

}  // namespace canfleet
