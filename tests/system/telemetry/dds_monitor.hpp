#pragma once
/// @file A test-side DDS monitor for system tests: a participant, a FleetReader and the model
/// `canfleet top`/`watch` use (tools::FleetView), polled from the test's thread.
#include <algorithm>
#include <chrono>
#include <functional>
#include <string>
#include <vector>

#include "telemetry/dds.hpp"
#include "telemetry/fleet_reader.hpp"
#include "tests/system/support/child_process.hpp"
#include "tools/telemetry/fleet_view.hpp"

namespace canfleet::system_test {

/// A test-side monitor: a participant, a FleetReader and the model tools use.
class Monitor {
 public:
  /// `config_file`: the Cyclone configuration the publishers use (the loopback one in tests).
  Monitor(std::uint32_t domain, const std::string& config_file)
      : participant_({.domain_id = domain, .config_file = config_file}),
        view_(std::chrono::system_clock::now()),
        reader_(participant_,
                {.node_status = [this](const auto& s, const auto& m) { view_.Apply(s, m, &events_); },
                 .emcy = [this](const auto& s, const auto& m) { view_.Apply(s, m, &events_); },
                 .io = {},
                 .bus_stats = [this](const auto& s, const auto& m) { view_.Apply(s, m, &events_); },
                 .fault = [this](const auto& s, const auto& m) { view_.Apply(s, m, &events_); },
                 .verdict = [this](const auto& s, const auto& m) { view_.Apply(s, m, &events_); },
                 .scenario = [this](const auto& s, const auto& m) { view_.Apply(s, m, &events_); }}) {}

  bool Until(const std::function<bool()>& condition, std::chrono::milliseconds timeout = kPatience) {
    return WaitUntil(
        [&] {
          reader_.Poll();
          return condition();
        },
        timeout);
  }
  const tools::FleetView& view() const { return view_; }
  const std::vector<tools::FleetEvent>& events() const { return events_; }
  bool Has(const std::function<bool(const tools::FleetEvent&)>& match) const {
    return std::any_of(events_.begin(), events_.end(), match);
  }
  /// Waits until an event matching `match` has arrived.
  bool UntilEvent(const std::function<bool(const tools::FleetEvent&)>& match,
                  std::chrono::milliseconds timeout = kPatience) {
    return Until([&] { return Has(match); }, timeout);
  }
  const tools::NodeRow* Node(const std::string& bus, std::uint8_t id) const {
    const auto it = view_.nodes().find({bus, id});
    return it == view_.nodes().end() ? nullptr : &it->second;
  }

 private:
  telemetry::Participant participant_;
  tools::FleetView view_;
  std::vector<tools::FleetEvent> events_;
  telemetry::FleetReader reader_;
};

}  // namespace canfleet::system_test
