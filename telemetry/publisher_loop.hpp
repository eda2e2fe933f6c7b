#pragma once
/// @file The thread every telemetry publisher writes from (internal to telemetry/).
///
/// Threading contract: callers (the node's event loop, the broker) only copy a plain snapshot into
/// a pending slot under a mutex and, for the first change since the thread last looked, notify a
/// condition variable. They never wait for DDS, never allocate (for fixed-size snapshots) and never
/// hold the lock for more than that copy. The loop thread does every DDS write:
///  - events (EMCY, faults) are queued and written as soon as the thread wakes;
///  - snapshots are sampled at most once per `min_interval` (coalescing: intermediate values are
///    overwritten, the latest wins), written at once when they changed and at least every `period`.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>
#include <utility>

namespace canfleet::telemetry {

class PublisherLoop {
 public:
  using Clock = std::chrono::steady_clock;

  /// Blocks until everything handed over before the call has been written (tests, shutdown).
  void Flush();

 protected:
  explicit PublisherLoop(std::chrono::milliseconds min_interval) : min_interval_(min_interval) {}
  ~PublisherLoop();

  /// Starts the thread; the derived constructor calls this last (the thread calls virtuals).
  void Start();
  /// Stops and joins the thread after a final Publish(force); the derived destructor calls this first.
  void Stop();

  /// The caller-side mutex guarding the derived class's pending slots.
  std::mutex& mutex() { return mutex_; }
  /// Call with mutex() held after updating a pending snapshot; returns true if the caller must
  /// call Notify() after unlocking (first change since the loop last sampled).
  bool MarkInputLocked() { return !std::exchange(input_pending_, true); }
  /// Call with mutex() held after queueing an event; events wake the loop at once.
  bool MarkEventLocked() { return !std::exchange(event_pending_, true); }
  void Notify() { wake_.notify_one(); }

  /// With mutex() held: move pending snapshots (if `inputs`) and queued events to thread-private state.
  virtual void ConsumeLocked(bool inputs) = 0;
  /// Without the lock: write what is due. `force` writes every pending change regardless of
  /// min_interval (flush, stop). Returns the next time the loop must run even without input.
  virtual Clock::time_point Publish(Clock::time_point now, bool force) = 0;

  std::chrono::milliseconds min_interval() const { return min_interval_; }

 private:
  void Run();

  const std::chrono::milliseconds min_interval_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable flushed_;
  bool input_pending_ = false;
  bool event_pending_ = false;
  bool stop_ = false;
  std::uint64_t flush_requested_ = 0;
  std::uint64_t flush_done_ = 0;
  std::thread thread_;
};

}  // namespace canfleet::telemetry
