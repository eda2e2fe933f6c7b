#pragma once
/// @file What the orchestrator publishes: BusStats per bus and ScenarioStatus per scenario (on
/// change and every period), FaultEvent and Verdict events. Same threading as NodeTelemetry
/// (publisher_loop.hpp): callers copy, one thread writes.
///
/// @code
///   telemetry::OrchestratorTelemetry telemetry(participant);
///   telemetry::BusStatsSnapshot stats{.bus = "can0", .bitrate = 500000, .mode = "realtime", ...};
///   telemetry.UpdateBusStats(stats);          // e.g. from the broker's 1 s statistics timer
///   telemetry.PublishFault({.bus = "can0", .fault_id = 3, .action = FaultAction::kInjected,
///                           .kind = "drop", .target_node = 5, .parameters = {{"cob_id", "0x705"}}});
/// @endcode

#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "telemetry/dds.hpp"
#include "telemetry/node_telemetry.hpp"
#include "telemetry/publisher_loop.hpp"
#include "telemetry/types.hpp"

namespace canfleet::telemetry {

/// One bus's statistics. Bus and mode names fit std::string's small-string buffer (<= 15
/// characters), so a copy does not allocate.
struct BusStatsSnapshot {
  std::string bus{};
  std::uint32_t bitrate = 0;
  std::string mode{};
  float load_percent = 0;
  float frames_per_second = 0;
  std::uint64_t frames_total = 0;
  std::uint64_t error_frames = 0;
  std::uint16_t node_count = 0;
  std::uint8_t top_cob_id_count = 0;
  std::array<CobIdRate, kMaxTopCobIds> top_cob_ids{};
  double simulated_s = 0;  ///< mode "virtual": simulated time of the bus
  float speed_factor = 0;  ///< mode "virtual": simulated / real seconds achieved
};

/// True if the configuration or the error picture changed (bitrate, mode, node count, error
/// frames): those go out at once; rates and loads only every period.
bool BusStatsChanged(const BusStatsSnapshot& a, const BusStatsSnapshot& b);

/// A fault injected into or cleared from a bus. Faults are rare: this one may allocate.
struct FaultSnapshot {
  std::string bus{};
  std::uint32_t fault_id = 0;
  FaultAction action = FaultAction::kInjected;
  std::string kind{};
  std::uint8_t target_node = 0;                                   ///< 0 = the whole bus
  std::vector<std::pair<std::string, std::string>> parameters{};  ///< at most kMaxFaultParameters
  BusTime bus_time{};
};

/// One decided expectation. Verdicts are rare: this one may allocate.
struct VerdictSnapshot {
  std::string source{};     ///< the topology file as given; a longer one than 127 keeps its end
  std::uint16_t index = 0;  ///< among the file's expectations; kFileVerdictIndex: the file itself
  std::string scenario{};
  std::uint32_t cycle = 1;
  VerdictResult result = VerdictResult::kPass;
  std::string name{};
  std::uint32_t line = 0;
  std::string text{};  ///< the whole result line; published cut at a word boundary beyond 1023
  double scenario_time_s = 0;
};

/// Where a scenario stands (keyed by source). Written at once when anything but the clock changed,
/// and every period.
struct ScenarioStatusSnapshot {
  std::string source{};
  std::string scenario{};
  std::string time_mode{};  ///< "real" or "virtual"
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
};

/// True if anything but the scenario clock changed: that goes out at once.
bool ScenarioStatusChanged(const ScenarioStatusSnapshot& a, const ScenarioStatusSnapshot& b);

/// The key a scenario's source is published under: itself when it fits Verdict.source
/// (string<127>), else "..." and its last characters (the file name survives).
std::string SourceKey(const std::string& source);

struct OrchestratorTelemetryOptions {
  std::chrono::milliseconds period{1000};
  std::chrono::milliseconds min_interval{20};
  std::size_t fault_queue = 256;
};

class OrchestratorTelemetry final : private PublisherLoop {
 public:
  /// Creates topics and writers (throws DdsError) and starts the publisher thread.
  explicit OrchestratorTelemetry(const Participant& participant, OrchestratorTelemetryOptions options = {});
  /// The same on simulated time (tests): no thread; publication runs on `scheduler`'s timers, from
  /// the thread that advances it, which is also the only thread that may call the methods below.
  OrchestratorTelemetry(const Participant& participant, OrchestratorTelemetryOptions options,
                        Scheduler& scheduler);
  ~OrchestratorTelemetry();
  OrchestratorTelemetry(const OrchestratorTelemetry&) = delete;
  OrchestratorTelemetry& operator=(const OrchestratorTelemetry&) = delete;

  /// Hands over one bus's statistics (keyed by stats.bus). Any thread; never blocks on DDS.
  /// Throws std::invalid_argument for a bus name longer than kMaxBusName.
  void UpdateBusStats(const BusStatsSnapshot& stats);
  /// Disposes a bus's BusStats instance (the bus was removed).
  void RemoveBus(const std::string& bus);
  /// Queues a fault event for immediate publication. A parameter value longer than 255 characters
  /// is cut at a word boundary and ends in "..." (FaultParameter.value).
  void PublishFault(FaultSnapshot fault);
  /// Queues a verdict for immediate publication (the same queue as faults).
  void PublishVerdict(VerdictSnapshot verdict);
  /// Hands over where a scenario stands (keyed by status.source). Any thread; never blocks on DDS.
  void UpdateScenario(const ScenarioStatusSnapshot& status);
  /// Disposes a scenario's ScenarioStatus (its fleet stopped).
  void RemoveScenario(const std::string& source);

  using PublisherLoop::Flush;
  PublisherStats stats() const;

 private:
  struct Impl;
  void ConsumeLocked(bool inputs) override;
  void Init(const Participant& participant, OrchestratorTelemetryOptions options);
  TimePoint Publish(TimePoint now, bool force) override;

  std::unique_ptr<Impl> impl_;
};

}  // namespace canfleet::telemetry
