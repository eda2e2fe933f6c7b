#pragma once
/// @file The one clock of canfleet. Every protocol timer (heartbeat, event timer, inhibit time,
/// SYNC window, RPDO deadline, SDO and LSS timeouts, function-block ticks) is a Timer on a Scheduler.
/// Drivers decide what time is: SimulatedScheduler (tests advance it by hand) and AsioScheduler
/// (real time). The seam can say "my next deadline is T" (NextDeadline) and be told "advance to T"
/// (AdvanceTo), which is all a lock-step driver granted by the orchestrator will need.

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

namespace canfleet {

/// The scheduler's time line: nanoseconds since the scheduler started.
struct SchedulerClock {
  using rep = std::int64_t;
  using period = std::nano;
  using duration = std::chrono::nanoseconds;
  using time_point = std::chrono::time_point<SchedulerClock>;
  static constexpr bool is_steady = true;
};
using TimePoint = SchedulerClock::time_point;
using Duration = SchedulerClock::duration;

class Timer;

/// Owns the queue of armed timers. Not thread-safe: used from the thread of one event loop.
class Scheduler {
 public:
  Scheduler() = default;
  Scheduler(const Scheduler&) = delete;
  Scheduler& operator=(const Scheduler&) = delete;
  virtual ~Scheduler();

  /// The current time. Inside a timer callback it is that timer's deadline (simulated time) or
  /// the real time of the call (real-time drivers).
  virtual TimePoint Now() const = 0;

  /// The earliest deadline of any armed timer.
  std::optional<TimePoint> NextDeadline() const;

  /// Number of armed timers (for tests and leak checks).
  std::size_t ArmedCount() const { return heap_.size(); }

 protected:
  /// Runs every timer whose deadline is at or before `limit`, earliest first (ties in arming order).
  /// `on_each` is called with each deadline before its callback runs, so a simulated driver can set
  /// its clock. A callback may arm or cancel any timer, including itself.
  void RunDue(TimePoint limit, const std::function<void(TimePoint)>& on_each);

  /// Called whenever the earliest deadline may have changed (a real-time driver re-arms its OS timer).
  virtual void OnNextDeadlineChanged() {}

 private:
  friend class Timer;
  void Arm(Timer& timer, TimePoint deadline);
  void Disarm(Timer& timer);
  bool Before(const Timer* a, const Timer* b) const;
  void SiftUp(std::size_t i);
  void SiftDown(std::size_t i);
  void Swap(std::size_t i, std::size_t j);

  std::vector<Timer*> heap_;  // indexed binary min-heap; Timer::heap_index_ points back into it
  std::uint64_t next_sequence_ = 0;
};

/// A one-shot timer with a fixed callback, re-armable without allocation.
/// Destroying it cancels it. Must not outlive its Scheduler.
class Timer {
 public:
  Timer(Scheduler& scheduler, std::function<void()> on_expiry);
  Timer(const Timer&) = delete;
  Timer& operator=(const Timer&) = delete;
  ~Timer();

  /// Arms (or re-arms) the timer for an absolute deadline.
  void StartAt(TimePoint deadline);
  /// Arms (or re-arms) the timer `delay` from now.
  void StartAfter(Duration delay);
  void Cancel();
  bool Armed() const { return heap_index_ != kNotArmed; }
  /// The last deadline the timer was armed for (still valid inside its own callback).
  TimePoint Deadline() const { return deadline_; }

 private:
  friend class Scheduler;
  static constexpr std::size_t kNotArmed = static_cast<std::size_t>(-1);
  Scheduler& scheduler_;
  std::function<void()> on_expiry_;
  TimePoint deadline_{};
  std::uint64_t sequence_ = 0;
  std::size_t heap_index_ = kNotArmed;
};

/// Simulated time for unit tests: time stands still until the test advances it.
class SimulatedScheduler final : public Scheduler {
 public:
  TimePoint Now() const override { return now_; }
  /// Moves time forward by `delay`, firing every timer that falls due on the way, each at its own
  /// deadline.
  void Advance(Duration delay) { AdvanceTo(now_ + delay); }
  void AdvanceTo(TimePoint t);
  /// Fires timers until none is armed or `limit` is reached; returns the time reached.
  TimePoint RunUntilIdle(Duration limit);

 private:
  TimePoint now_{};
};

}  // namespace canfleet
