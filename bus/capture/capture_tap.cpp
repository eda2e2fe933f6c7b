#include "bus/capture/capture_tap.hpp"

#include <chrono>

namespace canfleet::capture {

WallTime WallClockOrigin(const Scheduler& scheduler) {
  const auto now = std::chrono::time_point_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now());
  return now - scheduler.Now().time_since_epoch();
}

void CaptureTap::Deliver(std::span<const broker::TimedFrame> frames) {
  for (const auto& f : frames)
    writer_.Write(f.frame, origin_ + f.time);
  frames_ += frames.size();
}

}  // namespace canfleet::capture
