#pragma once
/// @file COB-IDs and node-ID rules shared by the NMT slave and the error control services
/// (boot-up, heartbeat, node guarding; CiA 301 v4.2 §7.2.8.3.2, predefined connection set §7.3.5).

#include <cstdint>

namespace canfleet::canopen {

/// COB-ID of NMT module control (CiA 301 §7.2.8.3.1).
inline constexpr std::uint32_t kNmtCobId = 0x000;
/// Base COB-ID of boot-up, heartbeat and node guarding frames: 700h + node-ID.
inline constexpr std::uint32_t kErrorControlCobId = 0x700;

/// True for the node-IDs a CANopen device may use (CiA 301 §7.3.5: 1..127).
inline constexpr bool IsValidNodeId(std::uint8_t node_id) {
  return node_id >= 1 && node_id <= 127;
}

}  // namespace canfleet::canopen
