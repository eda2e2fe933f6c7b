#pragma once
/// @file Real-time driver of the scheduler on an Asio io_context: one steady_timer, always armed
/// for the earliest deadline.

#include <asio/io_context.hpp>
#include <asio/steady_timer.hpp>
#include <chrono>

#include "clock/scheduler.hpp"

namespace canfleet {

class AsioScheduler final : public Scheduler {
 public:
  explicit AsioScheduler(asio::io_context& io);
  ~AsioScheduler() override;

  TimePoint Now() const override;

 private:
  void OnNextDeadlineChanged() override;
  void Rearm();

  asio::steady_timer os_timer_;
  std::chrono::steady_clock::time_point epoch_;
  bool running_due_ = false;
};

}  // namespace canfleet
