#pragma once
/// @file Real-time driver of the scheduler for a thread of its own that sleeps on a condition
/// variable between deadlines (the telemetry publisher's thread): the thread waits with WaitUntil,
/// which returns at the earliest deadline or when another thread wakes it, then calls RunDueNow.
/// Time is the steady clock since the scheduler was made, as AsioScheduler's.

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>

#include "clock/scheduler.hpp"

namespace canfleet {

class ThreadScheduler final : public Scheduler {
 public:
  ThreadScheduler() : epoch_(std::chrono::steady_clock::now()) {}

  TimePoint Now() const override {
    return TimePoint{std::chrono::duration_cast<Duration>(std::chrono::steady_clock::now() - epoch_)};
  }

  /// With `lock` (on the mutex `cv` waits with) held: sleeps until the earliest armed deadline, or
  /// without limit when none is armed, or until `woken()` holds after a notification of `cv`.
  void WaitUntil(std::unique_lock<std::mutex>& lock, std::condition_variable& cv,
                 const std::function<bool()>& woken) const {
    if (const auto next = NextDeadline()) {
      cv.wait_until(lock, epoch_ + next->time_since_epoch(), woken);
    } else {
      cv.wait(lock, woken);
    }
  }

  /// Runs every timer that is due now (from the scheduler's own thread, without the lock).
  void RunDueNow() { RunDue(Now(), nullptr); }

 private:
  std::chrono::steady_clock::time_point epoch_;
};

}  // namespace canfleet
