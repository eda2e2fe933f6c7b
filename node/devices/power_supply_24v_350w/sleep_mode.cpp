#include "node/devices/power_supply_24v_350w/sleep_mode.hpp"

namespace canfleet::devices::ps {

SleepMode::SleepMode(Scheduler& scheduler, DevicePort& port, std::function<void(bool)> on_change)
    : port_(port), on_change_(std::move(on_change)), timer_(scheduler, [this] { FallAsleep(); }) {}

void SleepMode::Update(bool allowed, Duration delay) {
  if (asleep_) return;
  if (allowed && !allowed_) timer_.StartAfter(delay);
  if (!allowed) timer_.Cancel();
  allowed_ = allowed;
}

void SleepMode::Wake() {
  if (!asleep_) return;
  asleep_ = false;
  allowed_ = false;  // the delay starts over if sleep is still allowed
  port_.SetMuted(false);
  if (on_change_) on_change_(false);
}

void SleepMode::Reset() {
  timer_.Cancel();
  allowed_ = false;
  if (asleep_) {
    asleep_ = false;
    port_.SetMuted(false);
    if (on_change_) on_change_(false);
  }
}

void SleepMode::FallAsleep() {
  asleep_ = true;
  allowed_ = false;
  port_.SetMuted(true);
  if (on_change_) on_change_(true);
}

}  // namespace canfleet::devices::ps
