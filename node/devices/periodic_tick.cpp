#include "node/devices/periodic_tick.hpp"

#include <stdexcept>

namespace canfleet::devices {

PeriodicTick::PeriodicTick(Scheduler& scheduler, Duration period, std::function<void()> on_tick)
    : period_(period), on_tick_(std::move(on_tick)), timer_(scheduler, [this] { OnExpiry(); }) {
  if (period_ <= Duration::zero()) throw std::invalid_argument("PeriodicTick: period must be positive");
}

void PeriodicTick::Start() {
  timer_.StartAfter(period_);
}

void PeriodicTick::OnExpiry() {
  // Re-arm first, from the deadline rather than from "now", so the callback may stop the tick.
  timer_.StartAt(timer_.Deadline() + period_);
  ++count_;
  on_tick_();
}

}  // namespace canfleet::devices
