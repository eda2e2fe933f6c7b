#pragma once
/// @file Plain value types shared by the publishers (snapshots) and the readers (samples).
/// All trivially copyable, so a snapshot holding them copies with one memcpy.

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>

#include "bus/bus_port.hpp"
#include "vocabulary/nmt_state.hpp"

namespace canfleet::telemetry {

using canfleet::BusTime;
using canfleet::ControllerState;
using canfleet::canopen::NmtState;

/// Longest bus name (IDL string<15>); longer names are rejected when a publisher is created.
inline constexpr std::size_t kMaxBusName = 15;
/// 1016h has sub-indices 1..127 (CiA 301 §7.5.2.33).
inline constexpr std::size_t kMaxHeartbeatConsumers = 127;
/// IDL bounds of IoSnapshot.inputs/outputs, BusStats.top_cob_ids and FaultEvent.parameters.
inline constexpr std::size_t kMaxIoChannels = 64;
inline constexpr std::size_t kMaxTopCobIds = 16;
inline constexpr std::size_t kMaxFaultParameters = 8;

/// State of one heartbeat consumer entry (CiA 301 §7.2.8.3.2): unknown until the first heartbeat.
enum class HeartbeatConsumerState : std::uint8_t { kUnknown, kActive, kTimedOut };

struct HeartbeatConsumerInfo {
  std::uint8_t node_id = 0;
  std::uint16_t time_ms = 0;  ///< consumer heartbeat time from 1016h
  HeartbeatConsumerState state = HeartbeatConsumerState::kUnknown;
  std::optional<NmtState> last_state{};  ///< what the monitored node last reported

  friend bool operator==(const HeartbeatConsumerInfo&, const HeartbeatConsumerInfo&) = default;
};

/// One EMCY frame (CiA 301 §7.2.7.3.1): code, 1001h, five manufacturer bytes, when it was on the bus.
struct EmcyInfo {
  std::uint16_t code = 0;
  std::uint8_t error_register = 0;
  std::array<std::uint8_t, 5> manufacturer{};
  BusTime bus_time{};

  friend bool operator==(const EmcyInfo&, const EmcyInfo&) = default;
};

enum class FaultAction : std::uint8_t { kInjected, kCleared };

struct CobIdRate {
  std::uint32_t cob_id = 0;
  float frames_per_second = 0;

  friend bool operator==(const CobIdRate&, const CobIdRate&) = default;
};

const char* ToString(HeartbeatConsumerState state);
const char* ToString(FaultAction action);
/// Short NMT state names for tables: "INIT", "PREOP", "OPER", "STOP", "?" (nullopt).
const char* ShortName(std::optional<NmtState> state);
/// Short controller names: "active", "passive", "bus-off".
const char* ShortName(ControllerState state);

}  // namespace canfleet::telemetry
