#pragma once
/// @file The loop every telemetry publisher writes from (internal to telemetry/).
///
/// Threading contract: callers (the node's event loop, the broker) only copy a plain snapshot into
/// a pending slot under a mutex and, for the first change since the loop last looked, wake the
/// loop. They never wait for DDS, never allocate (for fixed-size snapshots) and never hold the
/// lock for more than that copy. The loop does every DDS write:
///  - events (EMCY, faults) are queued and written as soon as the loop wakes;
///  - snapshots are sampled at most once per `min_interval` (coalescing: intermediate values are
///    overwritten, the latest wins), written at once when they changed and at least every `period`.
///
/// Time: the loop's one timer is a Timer on a Scheduler (clock/scheduler.hpp), in either of two
/// ways of running it:
///  - real time (the programs): a thread of the loop's own drives a ThreadScheduler;
///  - simulated time (tests): no thread; the timer runs on the caller's Scheduler (a
///    SimulatedScheduler), from the thread that advances it, which is then also the only thread
///    that hands anything over.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>

#include "clock/scheduler.hpp"
#include "clock/thread_scheduler.hpp"

namespace canfleet::telemetry {

class PublisherLoop {
 public:
  /// Returns once everything handed over before the call has been written (tests, shutdown).
  void Flush();

 protected:
  /// Real time: a thread of its own (started by Start()).
  explicit PublisherLoop(std::chrono::milliseconds min_interval);
  /// Simulated time: the loop's timer runs on `scheduler`, which must outlive the loop.
  PublisherLoop(std::chrono::milliseconds min_interval, Scheduler& scheduler);
  ~PublisherLoop();

  /// Starts the loop; the derived constructor calls this last (the loop calls virtuals).
  void Start();
  /// Stops the loop after a final Publish(force) (and joins its thread); the derived destructor
  /// calls this first.
  void Stop();

  /// The caller-side mutex guarding the derived class's pending slots.
  std::mutex& mutex() { return mutex_; }
  /// Call with mutex() held after updating a pending snapshot; returns true if the caller must
  /// call Notify() after unlocking (first change since the loop last sampled).
  bool MarkInputLocked() { return Wakes(!std::exchange(input_pending_, true)); }
  /// Call with mutex() held after queueing an event; events wake the loop at once.
  bool MarkEventLocked() { return Wakes(!std::exchange(event_pending_, true)); }
  void Notify();

  /// With mutex() held: move pending snapshots (if `inputs`) and queued events to loop-private state.
  virtual void ConsumeLocked(bool inputs) = 0;
  /// Without the lock: write what is due. `force` writes every pending change regardless of
  /// min_interval (flush, stop). Returns the next time the loop must run even without input.
  virtual TimePoint Publish(TimePoint now, bool force) = 0;

  std::chrono::milliseconds min_interval() const { return min_interval_; }
  /// The loop's time (for the derived class's own stamps, e.g. uptime).
  TimePoint Now() const { return scheduler_.Now(); }

 private:
  bool Wakes(bool first) {
    if (first) woken_ = true;
    return first;
  }
  /// On the loop's scheduler: arms the timer for what was handed over.
  void Schedule();
  /// The timer: samples, publishes, re-arms.
  void Cycle();
  /// The thread of the real-time mode.
  void Run();

  const std::chrono::milliseconds min_interval_;
  std::unique_ptr<ThreadScheduler> own_scheduler_;  ///< real time only
  Scheduler& scheduler_;
  Timer timer_;
  bool started_ = false;     ///< between Start() and Stop(); guarded by mutex_
  TimePoint next_due_{};     ///< loop-private: the next periodic publication
  TimePoint next_sample_{};  ///< loop-private: inputs are not sampled before this

  std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable flushed_;
  bool woken_ = false;  ///< something was handed over since the loop last looked
  bool input_pending_ = false;
  bool event_pending_ = false;
  bool stop_ = false;
  std::uint64_t flush_requested_ = 0;
  std::uint64_t flush_done_ = 0;
  std::thread thread_;
};

}  // namespace canfleet::telemetry
