#pragma once
/// @file The one clock of canfleet. Every protocol timer (heartbeat, event timer, inhibit time,
/// SYNC window, RPDO deadline, SDO and LSS timeouts, function-block ticks) is a Timer on a Scheduler.
/// Drivers decide what time is: SimulatedScheduler (tests advance it by hand) and AsioScheduler
/// (real time). The seam can say "my next deadline is T" (NextDeadline) and be told "advance to T"
/// (AdvanceTo), which is all a lock-step driver granted by the orchestrator will need.
///
/// Time is events (design decision 10): a periodic timer whose callback has nothing to do may be put
/// to sleep (Timer::Sleep). The scheduler then never wakes for it, yet keeps its place: every time
/// its deadline comes it is re-armed one period later, as a callback that only re-armed itself
/// would have done, so a Timer::Wake puts it back exactly where it would have been (the same
/// instants, the same order among timers due at the same instant).

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

/// Lock-step virtual time grants a node process as far as nothing it listens to can reach it
/// (issue 34, orchestrator/transport/grant_horizon.hpp), which needs to know who may send what
/// when. A timer whose callback has one narrow effect says so (Timer::Confine): a node's heartbeat
/// producer sends only its heartbeat's identifier, a TPDO's event timer only the TPDO's.
struct TimerOutlook {
  /// The earliest timer that may do anything (not confined); nullopt: none is armed.
  std::optional<TimePoint> unconfined;
  /// For each confinement key of an armed timer, its earliest deadline (ascending keys).
  std::vector<std::pair<std::uint32_t, TimePoint>> confined;
};

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

  /// The earliest deadline of any armed timer (sleeping timers need no wake-up: not counted).
  std::optional<TimePoint> NextDeadline() const;

  /// Number of armed timers, sleeping ones excluded (for tests and leak checks).
  std::size_t ArmedCount() const { return heap_.size(); }
  /// Number of sleeping periodic timers (Timer::Sleep).
  std::size_t SleepingCount() const { return sleeping_.size(); }
  /// Callbacks run since construction: the work the clock caused (tests count wake-ups with it).
  std::uint64_t FiredCount() const { return fired_; }

  /// What the armed timers may do next (TimerOutlook); O(armed timers).
  void TakeOutlook(TimerOutlook& out) const;
  /// Inside a timer's callback, its confinement (Timer::Confine); Timer::kUnconfined elsewhere.
  std::uint32_t RunningConfinement() const { return running_confinement_; }
  /// Timers armed or woken by a confined callback that are not confined alike: each breaks the
  /// promise of that callback (its owner said it does only one thing).
  std::uint64_t ConfinementBreaches() const { return confinement_breaches_; }

 protected:
  /// Runs every timer whose deadline is at or before `limit`, earliest first (ties in arming order).
  /// `on_each` is called with each deadline before its callback runs, so a simulated driver can set
  /// its clock. A callback may arm or cancel any timer, including itself. Sleeping timers due on
  /// the way are re-armed one period on, in their place in that order, without a callback.
  void RunDue(TimePoint limit, const std::function<void(TimePoint)>& on_each);

  /// Called whenever the earliest deadline may have changed (a real-time driver re-arms its OS timer).
  virtual void OnNextDeadlineChanged() {}

 private:
  friend class Timer;
  using Heap = std::vector<Timer*>;
  void Arm(Timer& timer, TimePoint deadline);
  void Disarm(Timer& timer);
  void Sleep(Timer& timer, Duration period);
  void Wake(Timer& timer);
  /// Re-arms, without their callbacks, the sleeping timers that come before (deadline, sequence).
  void AdvanceSleepers(TimePoint deadline, std::uint64_t sequence);
  /// Outside RunDue: the sleeping timers due by Now() have come, before anything armed now.
  void CatchUpSleepers();
  static bool Before(const Timer* a, const Timer* b);
  void Insert(Heap& heap, Timer& timer);
  void Remove(Heap& heap, Timer& timer);
  static void SiftUp(Heap& heap, std::size_t i);
  static void SiftDown(Heap& heap, std::size_t i);
  static void Swap(Heap& heap, std::size_t i, std::size_t j);

  Heap heap_;      // armed timers: indexed binary min-heap; Timer::heap_index_ points back into it
  Heap sleeping_;  // sleeping timers, the same way (Timer::sleep_period_ > 0)
  std::uint64_t next_sequence_ = 0;
  std::uint64_t fired_ = 0;
  bool running_due_ = false;
  std::uint32_t running_confinement_ = 0xFFFF'FFFF;
  std::uint64_t confinement_breaches_ = 0;
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
  /// Armed and awake: the scheduler will run the callback at Deadline().
  bool Armed() const { return heap_index_ != kNotArmed && !Asleep(); }
  /// The last deadline the timer was armed for (still valid inside its own callback); for a
  /// sleeping timer, the deadline it has reached.
  TimePoint Deadline() const { return deadline_; }

  /// Puts an armed timer to sleep, as the timer of a periodic activity with nothing to do: from
  /// now on, each time its deadline comes the scheduler re-arms it for deadline + `period` (> 0)
  /// without running the callback and without waking up for it, exactly as a callback whose first
  /// action re-arms it one period on and which then does nothing. Wake() puts it back in its place.
  /// Re-arming or cancelling ends the sleep. No effect on a timer that is not armed.
  void Sleep(Duration period);
  /// A sleeping timer is armed again at the deadline it has reached, in the order it would have
  /// had (so its next callback comes at the instant, and among the timers due at that instant, it
  /// would have come if it had never slept). No effect on a timer that is not asleep.
  void Wake();
  bool Asleep() const { return sleep_period_ > Duration::zero(); }

  /// Anything: the default.
  static constexpr std::uint32_t kUnconfined = 0xFFFF'FFFF;
  /// With a node's 11-bit key: the frames are heartbeats (one state byte, never a boot-up), which
  /// a heartbeat consumer answers with nothing at once (wire::Acceptance.passive).
  static constexpr std::uint32_t kHeartbeat = 0x1000;
  /// States that the callback's only effect others may notice is the one `key` names, and that it
  /// arms no timer confined otherwise (TimerOutlook). On a node, `key` is the 11-bit identifier of
  /// the one frame it may send; a broker's bus confines its timer to the bus's own events.
  /// kUnconfined takes the promise back.
  void Confine(std::uint32_t key) { confinement_ = key; }
  std::uint32_t Confinement() const { return confinement_; }

 private:
  friend class Scheduler;
  static constexpr std::size_t kNotArmed = static_cast<std::size_t>(-1);
  Scheduler& scheduler_;
  std::function<void()> on_expiry_;
  TimePoint deadline_{};
  std::uint64_t sequence_ = 0;
  std::size_t heap_index_ = kNotArmed;  // into Scheduler::heap_, or sleeping_ while asleep
  Duration sleep_period_{0};            // > 0 while asleep
  std::uint32_t confinement_ = kUnconfined;
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
