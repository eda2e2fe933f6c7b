#pragma once
/// @file The third driver of the scheduler (design decision 2): time granted from outside. Lock-step
/// virtual time (orchestrator/broker/README.md "Virtual time") runs a node process on it, told by
/// the broker "advance to T", and the broker itself on another, advanced by its time conductor. Time
/// stands still between grants, as in SimulatedScheduler; unlike it, Now() may be read from another
/// thread (the telemetry publisher stamps its samples with it).

#include <atomic>

#include "clock/scheduler.hpp"

namespace canfleet {

class GrantedScheduler final : public Scheduler {
 public:
  TimePoint Now() const override { return TimePoint(Duration(now_ns_.load(std::memory_order_relaxed))); }

  /// Runs every timer due by `t`, each at its own deadline (Now() is that deadline inside its
  /// callback), then stands at `t`. A `t` in the past is now (time never goes back).
  void AdvanceTo(TimePoint t);

 private:
  void Set(TimePoint t) { now_ns_.store(t.time_since_epoch().count(), std::memory_order_relaxed); }
  std::atomic<std::int64_t> now_ns_{0};
};

}  // namespace canfleet
