#pragma once
/// @file What the orchestrator publishes about its buses (issue 7), taken from an in-process
/// broker::Broker:
///  - BusStats of every bus (Broker::Stats: bitrate, paced or not, load, frames/s, totals, error
///    frames, attached ports, busiest identifiers), sampled every period on the broker's own
///    Scheduler, so it reads the Broker on the thread that owns it;
///  - FaultEvents, on behalf of whoever injects faults (the fleet manager): injected, then cleared
///    with the same fault_id.
/// The DDS writes happen on telemetry::OrchestratorTelemetry's own thread; the calls here only copy.
///
/// @code
///   telemetry::Participant participant(dds_options);
///   telemetry::OrchestratorTelemetry publisher(participant);
///   broker::BrokerTelemetry telemetry(broker, scheduler, publisher);     // BusStats every second
///   const auto id = faults.Add(rule);                                    // the fleet manager's fault
///   telemetry.PublishFaultInjected({.bus = "can0", .fault_id = id, .kind = "drop", .target_node = 5,
///                                   .parameters = {{"cob_id", "0x705"}}});
///   faults.Remove(id);
///   telemetry.PublishFaultCleared("can0", id);
/// @endcode
///
/// Threading: like the Broker, every call on the thread that runs the scheduler's event loop.

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "clock/scheduler.hpp"
#include "orchestrator/broker/broker.hpp"
#include "telemetry/orchestrator_telemetry.hpp"

namespace canfleet::broker {

struct BrokerTelemetryOptions {
  /// How often every bus's statistics are sampled and handed to the publisher. The publisher
  /// writes a bus's sample at once when its configuration or error count changed, and at least
  /// every OrchestratorTelemetryOptions::period.
  std::chrono::milliseconds period{1000};
  /// Virtual time: the factor achieved so far (simulated / real seconds); the buses' mode is then
  /// "virtual" and their samples carry simulated time. Unset: real time.
  std::function<double()> virtual_time_factor{};
};

/// A fault as its injector describes it.
struct FaultReport {
  std::string bus{};
  /// Pairs the injection with its clearing, per bus (e.g. the FaultStage RuleId). 0: one is
  /// assigned (PublishFaultInjected returns it).
  std::uint32_t fault_id = 0;
  std::string kind{};            ///< e.g. "drop", "delay", "corrupt", "duplicate", "bus-off"
  std::uint8_t target_node = 0;  ///< 0 = the whole bus
  /// Shown by monitors as name=value; at most telemetry::kMaxFaultParameters are published.
  std::vector<std::pair<std::string, std::string>> parameters{};
};

/// BusStats as published for one broker::BusStats (pure: for tests). `top_ids` beyond
/// telemetry::kMaxTopCobIds are left out; a 29-bit identifier carries bit 31 (as SocketCAN's
/// CAN_EFF_FLAG).
telemetry::BusStatsSnapshot ToSnapshot(const BusStats& stats);

class BrokerTelemetry {
 public:
  /// Samples every bus at once, then every period. `broker`, `scheduler` and `publisher` must
  /// outlive this object.
  BrokerTelemetry(Broker& broker, Scheduler& scheduler, telemetry::OrchestratorTelemetry& publisher,
                  BrokerTelemetryOptions options = {});
  /// Stops sampling and disposes the BusStats of every bus it published (monitors drop them).
  ~BrokerTelemetry();
  BrokerTelemetry(const BrokerTelemetry&) = delete;
  BrokerTelemetry& operator=(const BrokerTelemetry&) = delete;

  /// Samples every bus now (also called by the timer). A bus that is gone from the broker is
  /// disposed.
  void Sample();

  /// Publishes that a fault was injected; returns its fault_id (report.fault_id, or a new one when
  /// 0). The report is kept until cleared, so the clearing carries the same kind, target and
  /// parameters.
  std::uint32_t PublishFaultInjected(FaultReport report);
  /// Publishes that fault `fault_id` of `bus` was cleared. False (and nothing published) when no
  /// such fault was published as injected.
  bool PublishFaultCleared(std::string_view bus, std::uint32_t fault_id);
  /// Faults published as injected and not cleared yet, per bus and fault_id.
  const std::map<std::pair<std::string, std::uint32_t>, FaultReport>& ActiveFaults() const { return active_; }

 private:
  void Publish(const FaultReport& report, telemetry::FaultAction action);
  BusTime Now() const;

  Broker& broker_;
  Scheduler& scheduler_;
  telemetry::OrchestratorTelemetry& publisher_;
  BrokerTelemetryOptions options_;
  std::set<std::string> published_;  ///< buses with a BusStats instance
  std::map<std::pair<std::string, std::uint32_t>, FaultReport> active_;
  std::uint32_t next_fault_id_ = 0x8000'0000;  ///< assigned ids: above any RuleId in practice
  Timer timer_;
};

}  // namespace canfleet::broker
