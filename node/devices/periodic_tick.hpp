#pragma once
/// @file A fixed-period device tick on the clock seam (design decision 2): function blocks run
/// every N ms as their manual says (the Quad samples inputs every 10 ms), from a canfleet::Timer
/// on the node's Scheduler. Deadlines advance by exactly one period from the previous deadline,
/// so the tick does not drift however late a real-time driver runs it.
///
/// On demand (design decision 10, "time is events"): given an `idle` test, the tick sleeps after
/// a tick that found nothing to do (Timer::Sleep) and Wake() resumes it. A sleeping tick costs
/// nothing, yet stays on its grid: a woken tick runs at the next instant it would have run anyway,
/// in the same order among timers due then, so the device behaves exactly as with a fixed tick as
/// long as the skipped ticks would have changed nothing. That is the owner's contract:
///  - `idle()`, asked after each tick, is true only if another tick with the same inputs would
///    change nothing (nothing in progress: no ramp, no filter settling, no measuring window...);
///  - Wake() is called whenever an input of the tick may change (a simulated input set, an
///    object written, an NMT state change, an error raised or cleared). A Wake() during the tick
///    itself (the tick wrote an object or moved an output) counts as "not idle": one more tick.

#include <cstdint>
#include <functional>

#include "clock/scheduler.hpp"

namespace canfleet::devices {

class PeriodicTick {
 public:
  /// @param period > 0. @param on_tick runs at every deadline; it may Stop() the tick.
  /// @param idle empty: a fixed tick that never sleeps; else the on-demand mode above.
  PeriodicTick(Scheduler& scheduler, Duration period, std::function<void()> on_tick,
               std::function<bool()> idle = {});
  PeriodicTick(const PeriodicTick&) = delete;
  PeriodicTick& operator=(const PeriodicTick&) = delete;

  /// First tick one period from now, then every period.
  void Start();
  void Stop() { timer_.Cancel(); }
  /// Started and not stopped (ticking or asleep).
  bool Running() const { return timer_.Armed() || timer_.Asleep(); }
  /// Sleeping until Wake().
  bool Asleep() const { return timer_.Asleep(); }
  /// Something the tick reads may have changed: it runs at its next instant on the grid.
  void Wake();
  Duration Period() const { return period_; }
  /// Ticks run since construction (not the skipped ones).
  std::uint64_t Count() const { return count_; }

 private:
  void OnExpiry();

  Duration period_;
  std::function<void()> on_tick_;
  std::function<bool()> idle_;
  std::uint64_t count_ = 0;
  bool woken_ = false;  ///< Wake() was called since the current (or last) tick began
  Timer timer_;
};

}  // namespace canfleet::devices
