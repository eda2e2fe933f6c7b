#include "clock/asio_scheduler.hpp"

namespace canfleet {

AsioScheduler::AsioScheduler(asio::io_context& io)
    : os_timer_(io), epoch_(std::chrono::steady_clock::now()) {}

AsioScheduler::~AsioScheduler() {
  os_timer_.cancel();
}

TimePoint AsioScheduler::Now() const {
  return TimePoint{std::chrono::duration_cast<Duration>(std::chrono::steady_clock::now() - epoch_)};
}

void AsioScheduler::OnNextDeadlineChanged() {
  // While RunDue is draining, callbacks re-arm timers; re-arm the OS timer once afterwards.
  if (!running_due_) Rearm();
}

void AsioScheduler::Rearm() {
  auto next = NextDeadline();
  if (!next) {
    os_timer_.cancel();
    return;
  }
  os_timer_.expires_at(epoch_ + next->time_since_epoch());
  os_timer_.async_wait([this](const asio::error_code& ec) {
    if (ec) return;  // cancelled: a newer deadline re-armed the timer
    running_due_ = true;
    RunDue(Now(), nullptr);
    running_due_ = false;
    Rearm();
  });
}

}  // namespace canfleet
