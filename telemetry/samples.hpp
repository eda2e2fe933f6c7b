#pragma once
/// @file Reader-side C++ values of the seven topics, converted from the idlc-generated C samples.
/// Tools and tests work on these; only telemetry/ touches the C types.

#include <chrono>
#include <compare>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "canfleet_telemetry.h"
#include "telemetry/types.hpp"

namespace canfleet::telemetry {

/// The key of NodeStatus and IoSnapshot.
struct NodeKey {
  std::string bus{};
  std::uint8_t node_id = 0;
  friend auto operator<=>(const NodeKey&, const NodeKey&) = default;
};

struct NodeStatusSample {
  std::string bus{};
  std::uint8_t node_id = 0;
  std::string device{};
  std::string name{};                   ///< the node's topology name ("" if it has none)
  std::optional<NmtState> nmt_state{};  ///< nullopt: unknown
  std::uint8_t error_register = 0;
  ControllerState controller_state = ControllerState::kErrorActive;
  std::uint16_t tec = 0;
  std::uint8_t rec = 0;
  std::uint16_t heartbeat_producer_ms = 0;
  std::vector<HeartbeatConsumerInfo> heartbeat_consumers{};
  std::uint64_t rpdo_count = 0;
  std::uint64_t tpdo_count = 0;
  std::chrono::milliseconds uptime{};
  std::optional<EmcyInfo> last_emcy{};
  std::chrono::milliseconds publish_period{};
  std::uint32_t serial = 0;

  NodeKey key() const { return {bus, node_id}; }
};

struct EmcySample {
  std::string bus{};
  std::uint8_t node_id = 0;
  EmcyInfo emcy{};
  std::uint32_t serial = 0;
};

struct IoValueSample {
  std::string name{};
  double value = 0;
  std::string unit{};
  std::string text{};  ///< a bool's or an enum's word ("true", "on"); "" for a number
  friend bool operator==(const IoValueSample&, const IoValueSample&) = default;
};

struct IoSnapshotSample {
  std::string bus{};
  std::uint8_t node_id = 0;
  std::vector<IoValueSample> inputs{};
  std::vector<IoValueSample> outputs{};
  std::uint32_t serial = 0;
};

struct BusStatsSample {
  std::string bus{};
  std::uint32_t bitrate = 0;
  std::string mode{};
  float load_percent = 0;
  float frames_per_second = 0;
  std::uint64_t frames_total = 0;
  std::uint64_t error_frames = 0;
  std::uint16_t node_count = 0;
  std::vector<CobIdRate> top_cob_ids{};
  std::uint32_t serial = 0;
  double simulated_s = 0;  ///< mode "virtual": simulated time of the bus
  float speed_factor = 0;  ///< mode "virtual": simulated / real seconds achieved
};

struct FaultEventSample {
  std::string bus{};
  std::uint32_t fault_id = 0;
  FaultAction action = FaultAction::kInjected;
  std::string kind{};
  std::uint8_t target_node = 0;  ///< 0 = the whole bus
  std::vector<std::pair<std::string, std::string>> parameters{};
  BusTime bus_time{};
  std::uint32_t serial = 0;
};

/// One decided expectation (the Verdict topic).
struct VerdictSample {
  std::string source{};  ///< the topology file
  std::uint16_t index = 0;
  std::string scenario{};
  std::uint32_t cycle = 0;
  VerdictResult result = VerdictResult::kPass;
  std::string name{};
  std::uint32_t line = 0;
  std::string text{};  ///< the result line as `canfleet test` prints it
  bool text_cut = false;
  double scenario_time_s = 0;
  std::uint32_t serial = 0;
};

/// Where a scenario stands (the ScenarioStatus topic).
struct ScenarioStatusSample {
  std::string source{};
  std::string scenario{};
  std::string time_mode{};
  double scenario_time_s = 0;
  std::uint32_t cycle = 0;
  bool running = false;
  std::uint16_t expectations = 0;
  std::uint16_t passed = 0;
  std::uint16_t failed = 0;
  std::uint16_t skipped = 0;
  std::uint16_t pending = 0;
  std::string step{};
  double step_time_s = 0;
  std::chrono::milliseconds publish_period{};
  std::uint32_t serial = 0;
};

NodeStatusSample FromDds(const canfleet_telemetry_NodeStatus& sample);
EmcySample FromDds(const canfleet_telemetry_Emcy& sample);
IoSnapshotSample FromDds(const canfleet_telemetry_IoSnapshot& sample);
BusStatsSample FromDds(const canfleet_telemetry_BusStats& sample);
FaultEventSample FromDds(const canfleet_telemetry_FaultEvent& sample);
VerdictSample FromDds(const canfleet_telemetry_Verdict& sample);
ScenarioStatusSample FromDds(const canfleet_telemetry_ScenarioStatus& sample);

// Enum mappings between our types and the IDL's.
canfleet_telemetry_NmtState ToDds(std::optional<NmtState> state);
std::optional<NmtState> FromDds(canfleet_telemetry_NmtState state);
canfleet_telemetry_ControllerState ToDds(ControllerState state);
ControllerState FromDds(canfleet_telemetry_ControllerState state);
canfleet_telemetry_HeartbeatConsumerState ToDds(HeartbeatConsumerState state);
HeartbeatConsumerState FromDds(canfleet_telemetry_HeartbeatConsumerState state);
canfleet_telemetry_FaultAction ToDds(FaultAction action);
FaultAction FromDds(canfleet_telemetry_FaultAction action);
canfleet_telemetry_VerdictResult ToDds(VerdictResult result);
VerdictResult FromDds(canfleet_telemetry_VerdictResult result);
// The same from an enum field's integer, as a received sample is read: a hostile or newer writer
// may send a value the IDL enum lacks, and loading it as the C enum would be undefined behaviour
// (UBSan's -fsanitize=enum); unknown values map as the functions above document.
std::optional<NmtState> NmtStateFromRaw(std::int32_t state);
ControllerState ControllerStateFromRaw(std::int32_t state);
HeartbeatConsumerState HeartbeatConsumerStateFromRaw(std::int32_t state);
FaultAction FaultActionFromRaw(std::int32_t action);
VerdictResult VerdictResultFromRaw(std::int32_t result);
/// An IDL enum field of a sample as its integer, without loading it as the enum.
template <typename Enum>
std::int32_t RawEnum(const Enum& field) {
  static_assert(sizeof(Enum) == sizeof(std::int32_t), "IDL enums are 32-bit");
  std::int32_t raw = 0;
  std::memcpy(&raw, &field, sizeof raw);
  return raw;
}

/// Copies `text` into a bounded IDL string (char[N]), truncating to N-1 characters.
template <std::size_t N>
void CopyBounded(char (&out)[N], std::string_view text) {
  const std::size_t n = text.size() < N - 1 ? text.size() : N - 1;
  text.copy(out, n);
  out[n] = '\0';
}

/// Copies `text` into a bounded IDL string, cut at a word boundary with kCutMarker when it does
/// not fit (CutAtWord), never mid-word silently. Does not allocate. Returns whether it was cut.
template <std::size_t N>
bool CopyBoundedAtWord(char (&out)[N], std::string_view text) {
  const std::size_t n = CutAtWord(text, N - 1);
  text.copy(out, n);
  if (n == text.size()) {
    out[n] = '\0';
    return false;
  }
  kCutMarker.copy(out + n, kCutMarker.size());
  out[n + kCutMarker.size()] = '\0';
  return true;
}

/// Reads a bounded IDL string; never reads past the array even if it is not terminated.
template <std::size_t N>
std::string FromBounded(const char (&text)[N]) {
  std::size_t n = 0;
  while (n < N && text[n] != '\0')
    ++n;
  return std::string(text, n);
}

}  // namespace canfleet::telemetry
