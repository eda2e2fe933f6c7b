#pragma once
/// @file Real-time driver of the scheduler on an Asio io_context: one steady_timer, always armed
/// for the earliest deadline that lies in the future; deadlines already due run from a posted
/// handler instead (no OS timer round trip).

#include <asio/io_context.hpp>
#include <asio/steady_timer.hpp>
#include <chrono>
#include <memory>
#include <optional>

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
  void RunDueNow();

  asio::steady_timer os_timer_;
  std::chrono::steady_clock::time_point epoch_;
  bool running_due_ = false;
  /// A RunDueNow handler is posted and has not run yet.
  bool run_posted_ = false;
  /// The deadline os_timer_ is waiting for, while it waits.
  std::optional<TimePoint> os_deadline_;
  /// Posted handlers check it: the io_context may outlive the scheduler.
  std::shared_ptr<int> alive_ = std::make_shared<int>(0);
};

}  // namespace canfleet
