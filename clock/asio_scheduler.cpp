#include "clock/asio_scheduler.hpp"

#include <asio/post.hpp>

namespace canfleet {

AsioScheduler::AsioScheduler(asio::io_context& io)
    : os_timer_(io), epoch_(std::chrono::steady_clock::now()) {}

AsioScheduler::~AsioScheduler() {
  alive_.reset();
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
    if (os_deadline_) {
      os_timer_.cancel();
      os_deadline_.reset();
    }
    return;
  }
  if (*next <= Now()) {
    // Already due (a zero-delay timer, e.g. an unpaced bus's round): run it from the event loop's
    // queue. An OS timer set in the past costs two timerfd_settime calls, an epoll_wait and a
    // timer interrupt per expiry. RunDue keeps the order (deadline, then arming order) either way.
    if (!run_posted_) {
      run_posted_ = true;
      asio::post(os_timer_.get_executor(), [this, alive = std::weak_ptr<int>(alive_)] {
        if (alive.expired()) return;
        run_posted_ = false;
        RunDueNow();
      });
    }
    return;
  }
  if (os_deadline_ == next) return;  // already waiting for it
  os_deadline_ = next;
  os_timer_.expires_at(epoch_ + next->time_since_epoch());
  os_timer_.async_wait([this](const asio::error_code& ec) {
    if (ec) return;  // cancelled: a newer deadline re-armed the timer
    os_deadline_.reset();
    RunDueNow();
  });
}

void AsioScheduler::RunDueNow() {
  running_due_ = true;
  RunDue(Now(), nullptr);
  running_due_ = false;
  Rearm();
}

}  // namespace canfleet
