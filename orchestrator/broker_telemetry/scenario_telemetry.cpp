#include "orchestrator/broker_telemetry/scenario_telemetry.hpp"

#include <spdlog/spdlog.h>

#include <stdexcept>

namespace canfleet::broker {

ScenarioTelemetry::ScenarioTelemetry(Scheduler& scheduler, telemetry::OrchestratorTelemetry& publisher,
                                     Sampler sample, std::chrono::milliseconds period)
    : publisher_(publisher), sample_(std::move(sample)), period_(period), timer_(scheduler, [this] {
        Sample();
        timer_.StartAfter(std::chrono::duration_cast<Duration>(period_));
      }) {
  if (!sample_) throw std::invalid_argument("ScenarioTelemetry: no sampler");
  if (period_ <= std::chrono::milliseconds::zero())
    throw std::invalid_argument("ScenarioTelemetry: period must be > 0");
  Sample();
  timer_.StartAfter(std::chrono::duration_cast<Duration>(period_));
}

ScenarioTelemetry::~ScenarioTelemetry() {
  timer_.Cancel();
  if (!source_.empty()) publisher_.RemoveScenario(source_);
}

void ScenarioTelemetry::Sample() {
  const telemetry::ScenarioStatusSnapshot status = sample_();
  if (status.source.empty()) return;
  if (!source_.empty() && source_ != status.source) publisher_.RemoveScenario(source_);
  source_ = status.source;
  publisher_.UpdateScenario(status);
}

void ScenarioTelemetry::PublishVerdict(telemetry::VerdictSnapshot verdict) {
  const telemetry::ScenarioStatusSnapshot status = sample_();
  if (verdict.source.empty()) verdict.source = status.source;
  if (verdict.scenario.empty()) verdict.scenario = status.scenario;
  if (verdict.source.empty()) {
    spdlog::warn("telemetry: a verdict of no scenario file is not published");
    return;
  }
  Sample();
  publisher_.PublishVerdict(std::move(verdict));
}

}  // namespace canfleet::broker
