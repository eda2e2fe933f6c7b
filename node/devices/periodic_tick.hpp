#pragma once
/// @file A fixed-period device tick on the clock seam (design decision 2): function blocks run
/// every N ms as their manual says (the Quad samples inputs every 10 ms), from a canfleet::Timer
/// on the node's Scheduler. Deadlines advance by exactly one period from the previous deadline,
/// so the tick does not drift however late a real-time driver runs it.

#include <cstdint>
#include <functional>

#include "clock/scheduler.hpp"

namespace canfleet::devices {

class PeriodicTick {
 public:
  /// @param period > 0. @param on_tick runs at every deadline; it may Stop() the tick.
  PeriodicTick(Scheduler& scheduler, Duration period, std::function<void()> on_tick);
  PeriodicTick(const PeriodicTick&) = delete;
  PeriodicTick& operator=(const PeriodicTick&) = delete;

  /// First tick one period from now, then every period.
  void Start();
  void Stop() { timer_.Cancel(); }
  bool Running() const { return timer_.Armed(); }
  Duration Period() const { return period_; }
  /// Ticks run since construction.
  std::uint64_t Count() const { return count_; }

 private:
  void OnExpiry();

  Duration period_;
  std::function<void()> on_tick_;
  std::uint64_t count_ = 0;
  Timer timer_;
};

}  // namespace canfleet::devices
