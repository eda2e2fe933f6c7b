#pragma once
/// @file Plain value types shared by the publishers (snapshots) and the readers (samples).
/// All trivially copyable, so a snapshot holding them copies with one memcpy.

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>
#include <string_view>

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
/// Longest node name (NodeStatus.name, string<31>), I/O word (IoValue.text), fault parameter value
/// (FaultParameter.value), verdict line (Verdict.text) and scenario file (Verdict.source).
inline constexpr std::size_t kMaxNodeName = 31;
inline constexpr std::size_t kMaxIoText = 31;
inline constexpr std::size_t kMaxFaultValue = 255;
inline constexpr std::size_t kMaxVerdictText = 1023;
inline constexpr std::size_t kMaxScenarioSource = 127;
/// Verdict.index of the verdict about the file itself (its fleet did not start).
inline constexpr std::uint16_t kFileVerdictIndex = 0xFFFF;

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

/// The result of a decided expectation (Verdict.result).
enum class VerdictResult : std::uint8_t { kPass, kFail, kSkip, kError };

struct CobIdRate {
  std::uint32_t cob_id = 0;
  float frames_per_second = 0;

  friend bool operator==(const CobIdRate&, const CobIdRate&) = default;
};

const char* ToString(HeartbeatConsumerState state);
const char* ToString(FaultAction action);
/// "pass", "FAIL", "skip", "error": the words `canfleet test` starts its result lines with.
const char* ToString(VerdictResult result);

/// The NMT state as the CLI (`canfleet status`) and expectations write it: "initialising",
/// "stopped", "operational", "pre-operational" (vocabulary/nmt_state.hpp); "unknown" (nullopt).
const char* StateName(std::optional<NmtState> state);
/// The controller state as the CLI and expectations write it: "error-active", "error-passive",
/// "bus-off" (bus/bus_port.hpp).
const char* StateName(ControllerState state);

/// Where `text` is cut to fit `max` characters: at the last space at or before max - 3 (then
/// "..." follows), so that no word is cut; mid-word only when the first word alone is longer.
/// Returns text.size() when it fits.
std::size_t CutAtWord(std::string_view text, std::size_t max);
/// The marker a text cut by CutAtWord ends in.
inline constexpr std::string_view kCutMarker = "...";

}  // namespace canfleet::telemetry
