#include "telemetry/publisher_loop.hpp"

#include <algorithm>

namespace canfleet::telemetry {

PublisherLoop::PublisherLoop(std::chrono::milliseconds min_interval)
    : min_interval_(min_interval),
      own_scheduler_(std::make_unique<ThreadScheduler>()),
      scheduler_(*own_scheduler_),
      timer_(scheduler_, [this] { Cycle(); }) {}

PublisherLoop::PublisherLoop(std::chrono::milliseconds min_interval, Scheduler& scheduler)
    : min_interval_(min_interval), scheduler_(scheduler), timer_(scheduler_, [this] { Cycle(); }) {}

PublisherLoop::~PublisherLoop() {
  // Derived classes stop the loop in their destructor; this only guards against a forgotten Stop().
  if (thread_.joinable()) {
    {
      const std::lock_guard lock(mutex_);
      stop_ = true;
      woken_ = true;
    }
    wake_.notify_one();
    thread_.join();
  }
}

void PublisherLoop::Start() {
  {
    const std::lock_guard lock(mutex_);
    started_ = true;
  }
  next_due_ = next_sample_ = scheduler_.Now();  // first publication at once
  if (own_scheduler_) {
    thread_ = std::thread([this] { Run(); });
  } else {
    timer_.StartAt(next_due_);
  }
}

void PublisherLoop::Stop() {
  {
    const std::lock_guard lock(mutex_);
    if (!started_) return;
    started_ = false;
    stop_ = true;
    woken_ = true;
  }
  if (own_scheduler_) {
    wake_.notify_one();
    if (thread_.joinable()) thread_.join();
  } else {
    Cycle();
    timer_.Cancel();
  }
}

void PublisherLoop::Notify() {
  if (own_scheduler_) {
    wake_.notify_one();
  } else {
    Schedule();
  }
}

void PublisherLoop::Flush() {
  std::unique_lock lock(mutex_);
  if (!started_) return;
  const std::uint64_t ticket = ++flush_requested_;
  woken_ = true;
  if (!own_scheduler_) {
    lock.unlock();
    Cycle();  // simulated time: the caller's thread is the loop's
    return;
  }
  wake_.notify_one();
  flushed_.wait(lock, [&] { return flush_done_ >= ticket || stop_; });
}

void PublisherLoop::Schedule() {
  TimePoint at = next_due_;
  {
    const std::lock_guard lock(mutex_);
    woken_ = false;
    if (stop_ || event_pending_ || flush_requested_ != flush_done_) {
      at = scheduler_.Now();
    } else if (input_pending_) {
      at = std::min(at, std::max(scheduler_.Now(), next_sample_));  // not inside the sampling window
    }
  }
  if (!timer_.Armed() || at < timer_.Deadline()) timer_.StartAt(at);
}

void PublisherLoop::Cycle() {
  std::unique_lock lock(mutex_);
  const TimePoint now = scheduler_.Now();
  const bool sample_inputs = input_pending_ && now >= next_sample_;
  if (sample_inputs) {
    input_pending_ = false;
    next_sample_ = now + min_interval_;
  }
  event_pending_ = false;
  ConsumeLocked(sample_inputs);
  const std::uint64_t flush_ticket = flush_requested_;
  const bool force = stop_ || flush_ticket != flush_done_;
  if (force && input_pending_) {  // a flush or stop takes the latest values even inside the window
    input_pending_ = false;
    ConsumeLocked(true);
  }
  const bool inputs_wait = input_pending_;
  lock.unlock();

  next_due_ = Publish(now, force);

  if (force) {
    lock.lock();
    flush_done_ = flush_ticket;
    lock.unlock();
    flushed_.notify_all();
  }
  // Inputs that arrived inside the sampling window are taken when it ends.
  timer_.StartAt(inputs_wait ? std::min(next_due_, std::max(now, next_sample_)) : next_due_);
}

void PublisherLoop::Run() {
  auto& scheduler = *own_scheduler_;
  timer_.StartAt(next_due_);
  for (;;) {
    bool stopping;
    {
      std::unique_lock lock(mutex_);
      scheduler.WaitUntil(lock, wake_, [this] { return woken_; });
      stopping = stop_;
    }
    Schedule();
    scheduler.RunDueNow();
    if (stopping) return;
  }
}

}  // namespace canfleet::telemetry
