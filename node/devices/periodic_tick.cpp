#include "node/devices/periodic_tick.hpp"

#include <stdexcept>

namespace canfleet::devices {

PeriodicTick::PeriodicTick(Scheduler& scheduler, Duration period, std::function<void()> on_tick,
                           std::function<bool()> idle)
    : period_(period),
      on_tick_(std::move(on_tick)),
      idle_(std::move(idle)),
      timer_(scheduler, [this] { OnExpiry(); }) {
  if (period_ <= Duration::zero()) throw std::invalid_argument("PeriodicTick: period must be positive");
}

void PeriodicTick::Start() {
  timer_.StartAfter(period_);
}

void PeriodicTick::Wake() {
  woken_ = true;
  timer_.Wake();
}

void PeriodicTick::OnExpiry() {
  // Re-arm first, from the deadline rather than from "now", so the callback may stop the tick.
  // A sleeping timer stands for exactly this re-arm (Timer::Sleep), which keeps the grid and the
  // order among timers due at the same instant when the tick sleeps and wakes.
  timer_.StartAt(timer_.Deadline() + period_);
  ++count_;
  woken_ = false;
  on_tick_();
  if (idle_ && timer_.Armed() && !woken_ && idle_()) timer_.Sleep(period_);
}

}  // namespace canfleet::devices
