#pragma once
/// @file Helpers of the heartbeat tests: a comm-error sink that records calls as text, and a bus
/// listener that records when (simulated time) each frame went over the bus.

#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "bus/loopback_bus.hpp"
#include "clock/scheduler.hpp"
#include "node/canopen/common/comm_error.hpp"

namespace canfleet::test {

/// Records every OnCommError call as "<kind> <detail hex> on|off", e.g. "hb-timeout 20 on".
class RecordingSink final : public canopen::CommErrorSink {
 public:
  void OnCommError(const canopen::CommError& error, bool active) override {
    const char* kind = "other";
    switch (error.kind) {
      case canopen::CommErrorKind::kHeartbeatTimeout:
        kind = "hb-timeout";
        break;
      case canopen::CommErrorKind::kBootUpOfMonitored:
        kind = "boot-up";
        break;
      case canopen::CommErrorKind::kLifeGuardTimeout:
        kind = "life-guard";
        break;
      default:
        break;
    }
    char text[40];
    std::snprintf(text, sizeof text, "%s %02X %s", kind, error.detail, active ? "on" : "off");
    calls_.emplace_back(text);
  }
  /// Returns and forgets the calls so far.
  std::vector<std::string> Take() {
    auto out = std::move(calls_);
    calls_.clear();
    return out;
  }
  bool Empty() const { return calls_.empty(); }

 private:
  std::vector<std::string> calls_;
};

/// Records "<ms> <candump>" for every frame it receives, e.g. "100 70A#7F".
class TimedLog {
 public:
  TimedLog(LoopbackBus& bus, const Scheduler& scheduler) : port_(bus.Attach("log")) {
    port_.OnReceive([this, &scheduler](const CanFrame& frame, BusTime) {
      auto ms =
          std::chrono::duration_cast<std::chrono::milliseconds>(scheduler.Now().time_since_epoch()).count();
      entries_.push_back(std::to_string(ms) + " " + ToCandump(frame));
    });
  }
  std::vector<std::string> Take() {
    auto out = std::move(entries_);
    entries_.clear();
    return out;
  }

 private:
  LoopbackPort& port_;
  std::vector<std::string> entries_;
};

}  // namespace canfleet::test
