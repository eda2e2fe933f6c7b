#pragma once
/// @file What the orchestrator publishes about a running scenario (issue 29): its ScenarioStatus
/// (cycle, scenario clock, verdict counts, the step it is at), sampled on the fleet's Scheduler
/// every period and at once when a step begins or an expectation is decided, and a Verdict per
/// decided expectation: the same result line the orchestrator's log and `canfleet test` print.
/// The DDS writes happen on telemetry::OrchestratorTelemetry's own thread; the calls here only copy.
///
/// @code
///   broker::ScenarioTelemetry scenario(scheduler, publisher, [&] { return StatusOfTheScenario(); });
///   fleet.OnScenarioChange([&] { scenario.Sample(); });
///   fleet.OnExpectation([&](const scenario::Result& r) { scenario.PublishVerdict(VerdictOf(r)); });
/// @endcode
///
/// Threading: every call on the thread that runs the scheduler's event loop.

#include <chrono>
#include <functional>
#include <string>

#include "clock/scheduler.hpp"
#include "telemetry/orchestrator_telemetry.hpp"

namespace canfleet::broker {

class ScenarioTelemetry {
 public:
  using Sampler = std::function<telemetry::ScenarioStatusSnapshot()>;

  /// Samples at once, then every `period`. `scheduler` and `publisher` must outlive this object;
  /// `sample` is called on the scheduler's thread and gives the status (its source is the key).
  ScenarioTelemetry(Scheduler& scheduler, telemetry::OrchestratorTelemetry& publisher, Sampler sample,
                    std::chrono::milliseconds period = std::chrono::seconds(1));
  /// Disposes the scenario's ScenarioStatus (monitors drop the scenario line).
  ~ScenarioTelemetry();
  ScenarioTelemetry(const ScenarioTelemetry&) = delete;
  ScenarioTelemetry& operator=(const ScenarioTelemetry&) = delete;

  /// Hands the current status over now (a step began, the scenario started or ended).
  void Sample();
  /// Hands the current status over, then the verdict: a reader that shows the verdict finds the
  /// counts that include it. Fields the verdict leaves empty (source, scenario) are the status's.
  void PublishVerdict(telemetry::VerdictSnapshot verdict);

 private:
  telemetry::OrchestratorTelemetry& publisher_;
  Sampler sample_;
  std::chrono::milliseconds period_;
  std::string source_;  ///< of the latest sample: what the destructor removes
  Timer timer_;
};

}  // namespace canfleet::broker
