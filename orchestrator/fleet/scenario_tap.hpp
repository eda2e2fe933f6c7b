#pragma once
/// @file What the scenario's expectations see of a bus: a listen-only port (it never
/// acknowledges, so it changes nothing) that also receives error frames, and hands every frame to
/// the scenario runner with its bus time.

#include <span>
#include <string>

#include "orchestrator/broker/broker.hpp"
#include "orchestrator/capture/capture_tap.hpp"
#include "orchestrator/scenario/scenario_runner.hpp"

namespace canfleet::fleet {

/// A listen-only port that hands every frame of its bus to the scenario runner.
class ScenarioTap final : public broker::PortSink {
 public:
  ScenarioTap(broker::Broker& broker, std::string bus, scenario::ScenarioRunner& runner)
      : broker_(broker), bus_(std::move(bus)), runner_(runner) {
    port_ = broker_.Attach(bus_, "canfleet-scenario", *this, capture::CaptureTap::kAttachOptions);
  }
  ~ScenarioTap() override { broker_.Detach(port_); }
  ScenarioTap(const ScenarioTap&) = delete;
  ScenarioTap& operator=(const ScenarioTap&) = delete;

  void Deliver(std::span<const broker::TimedFrame> frames) override {
    for (const auto& timed : frames)
      runner_.Frame(bus_, timed.frame, TimePoint(timed.time));
  }
  void ControllerChanged(const ControllerEvent&) override {}

 private:
  broker::Broker& broker_;
  std::string bus_;
  scenario::ScenarioRunner& runner_;
  broker::PortId port_ = 0;
};

}  // namespace canfleet::fleet
