#include "telemetry/publisher_loop.hpp"

#include <algorithm>

namespace canfleet::telemetry {

PublisherLoop::~PublisherLoop() {
  // Derived classes stop the loop in their destructor; this only guards against a forgotten Stop().
  if (thread_.joinable()) {
    {
      const std::lock_guard lock(mutex_);
      stop_ = true;
    }
    wake_.notify_one();
    thread_.join();
  }
}

void PublisherLoop::Start() {
  thread_ = std::thread([this] { Run(); });
}

void PublisherLoop::Stop() {
  if (!thread_.joinable()) return;
  {
    const std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_one();
  thread_.join();
}

void PublisherLoop::Flush() {
  std::unique_lock lock(mutex_);
  if (!thread_.joinable()) return;
  const std::uint64_t ticket = ++flush_requested_;
  wake_.notify_one();
  flushed_.wait(lock, [&] { return flush_done_ >= ticket || stop_; });
}

void PublisherLoop::Run() {
  Clock::time_point next_due = Clock::now();  // first publication at once
  Clock::time_point next_sample = Clock::now();
  for (;;) {
    std::unique_lock lock(mutex_);
    const auto urgent = [&] { return stop_ || event_pending_ || flush_requested_ != flush_done_; };
    // Inputs are sampled at most once per min_interval: before next_sample only urgent work wakes us.
    if (Clock::now() < next_sample) {
      wake_.wait_until(lock, std::min(next_due, next_sample), urgent);
    }
    if (!urgent()) wake_.wait_until(lock, next_due, [&] { return urgent() || input_pending_; });

    const Clock::time_point now = Clock::now();
    const bool sample_inputs = input_pending_ && now >= next_sample;
    if (sample_inputs) {
      input_pending_ = false;
      next_sample = now + min_interval_;
    }
    event_pending_ = false;
    ConsumeLocked(sample_inputs);
    const std::uint64_t flush_ticket = flush_requested_;
    const bool stopping = stop_;
    const bool force = stopping || flush_ticket != flush_done_;
    if (force && input_pending_) {  // a flush or stop takes the latest values even inside the window
      input_pending_ = false;
      ConsumeLocked(true);
    }
    lock.unlock();

    next_due = Publish(now, force);

    if (force) {
      lock.lock();
      flush_done_ = flush_ticket;
      lock.unlock();
      flushed_.notify_all();
    }
    if (stopping) return;
  }
}

}  // namespace canfleet::telemetry
