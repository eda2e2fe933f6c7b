#pragma once
/// @file What a monitor knows about the fleet, built from telemetry samples, and the events
/// (EMCY, NMT/controller/error-register changes, faults) derived from them. No DDS here: tests feed
/// it samples directly.

#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "telemetry/fleet_reader.hpp"
#include "telemetry/samples.hpp"

namespace canfleet::tools {

using telemetry::BusStatsSample;
using telemetry::EmcySample;
using telemetry::FaultEventSample;
using telemetry::IoSnapshotSample;
using telemetry::NodeKey;
using telemetry::NodeStatusSample;
using telemetry::SampleMeta;
using telemetry::ScenarioStatusSample;
using telemetry::VerdictSample;
using WallTime = std::chrono::system_clock::time_point;

enum class EventKind : std::uint8_t {
  kNodeSeen,           ///< first status of a node
  kNodeGone,           ///< instance disposed (clean exit) or without writers (process died)
  kNmt,                ///< NMT state change
  kController,         ///< CAN controller fault-confinement change
  kErrorRegister,      ///< 1001h change
  kHeartbeatConsumer,  ///< a heartbeat consumer entry changed state (e.g. timed out)
  kEmcy,
  kFault,    ///< fault injected or cleared by the orchestrator
  kVerdict,  ///< an expectation of a scenario decided (the Verdict topic)
};

/// "seen", "gone", "nmt", "controller", "error-register", "hb-consumer", "emcy", "fault", "verdict".
const char* ToString(EventKind kind);
std::optional<EventKind> ParseEventKind(std::string_view text);

struct FleetEvent {
  WallTime time{};  ///< the publisher's source timestamp
  EventKind kind = EventKind::kNmt;
  std::string bus{};
  std::uint8_t node_id = 0;  ///< 0 for bus-wide faults and verdicts
  std::string name{};        ///< the node's topology name when known (NodeStatus.name)
  std::string from{};        ///< state changes: old and new value as text
  std::string to{};
  std::uint8_t peer_node = 0;  ///< kHeartbeatConsumer: the monitored node
  std::optional<EmcySample> emcy{};
  std::optional<FaultEventSample> fault{};
  std::optional<VerdictSample> verdict{};
  /// Happened before the monitor started (delivered from transient-local history).
  bool replay = false;
};

/// One EMCY of a node as the monitor received it (the Emcy topic), with its publication time.
struct EmcyRecord {
  EmcySample sample;
  WallTime time{};
};

/// EMCYs kept per node: the Emcy topic's history depth (keep-last 32 per node, telemetry/QOS.md),
/// so a monitor started late shows what the topic still holds.
inline constexpr std::size_t kEmcyHistory = 32;

struct NodeRow {
  NodeStatusSample status;
  bool alive = true;
  bool disposed = false;
  WallTime last_sample{};                 ///< source time of the latest status
  WallTime last_change{};                 ///< latest NMT/controller/error-register change (or first sighting)
  std::optional<EmcySample> last_emcy{};  ///< latest Emcy event (the status carries the code too)
  WallTime last_emcy_time{};
  std::deque<EmcyRecord> emcy_history{};  ///< oldest first, at most kEmcyHistory
  std::optional<IoSnapshotSample> io{};
};

/// A scenario as its ScenarioStatus shows it, and its latest verdicts.
struct ScenarioRow {
  ScenarioStatusSample status;
  bool alive = true;  ///< false once disposed (its fleet stopped) or without writers
  WallTime last_sample{};
};

struct BusRow {
  std::optional<BusStatsSample> stats{};
  std::map<std::uint32_t, FaultEventSample> active_faults{};  ///< by fault_id
};

class FleetView {
 public:
  /// @param started when the monitor started: older samples are history (FleetEvent::replay).
  explicit FleetView(WallTime started, std::size_t recent_capacity = 200);

  // Each Apply() updates the model and appends derived events to `events` (may be null).
  void Apply(const NodeStatusSample& sample, const SampleMeta& meta, std::vector<FleetEvent>* events);
  void Apply(const EmcySample& sample, const SampleMeta& meta, std::vector<FleetEvent>* events);
  void Apply(const IoSnapshotSample& sample, const SampleMeta& meta, std::vector<FleetEvent>* events);
  void Apply(const BusStatsSample& sample, const SampleMeta& meta, std::vector<FleetEvent>* events);
  void Apply(const FaultEventSample& sample, const SampleMeta& meta, std::vector<FleetEvent>* events);
  void Apply(const VerdictSample& sample, const SampleMeta& meta, std::vector<FleetEvent>* events);
  void Apply(const ScenarioStatusSample& sample, const SampleMeta& meta, std::vector<FleetEvent>* events);

  const std::map<NodeKey, NodeRow>& nodes() const { return nodes_; }
  const std::map<std::string, BusRow>& buses() const { return buses_; }
  /// Scenarios by source (the topology file).
  const std::map<std::string, ScenarioRow>& scenarios() const { return scenarios_; }
  /// The latest events, ordered by time (oldest first).
  const std::deque<FleetEvent>& recent() const { return recent_; }
  /// When the set of known nodes last grew (used by `top --once` to wait for discovery).
  WallTime last_new_node() const { return last_new_node_; }

 private:
  void Emit(FleetEvent event, std::vector<FleetEvent>* events);
  void ApplyStatus(const NodeStatusSample& sample, const SampleMeta& meta, std::vector<FleetEvent>* events);
  void MarkGone(const NodeKey& key, const SampleMeta& meta, std::vector<FleetEvent>* events);

  WallTime started_{};
  std::size_t recent_capacity_{};
  std::map<NodeKey, NodeRow> nodes_{};
  std::map<NodeKey, std::deque<EmcyRecord>> early_emcy_{};  ///< EMCYs of nodes not seen yet
  std::map<std::string, BusRow> buses_{};
  std::map<std::string, ScenarioRow> scenarios_{};
  std::deque<FleetEvent> recent_{};
  WallTime last_new_node_{};
};

/// True if the row shows a fault: bus-off, error register set, a heartbeat consumer timed out,
/// gone, or stale (no status for 3 publish periods).
bool IsFaulted(const NodeRow& row, WallTime now);
/// True if no status arrived for 3 publish periods (at least 3 s).
bool IsStale(const NodeRow& row, WallTime now);
bool IsStale(const ScenarioRow& row, WallTime now);

}  // namespace canfleet::tools
