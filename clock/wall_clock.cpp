#include "clock/wall_clock.hpp"

namespace canfleet {

WallTime WallClockOrigin(const Scheduler& scheduler) {
  const auto now = std::chrono::time_point_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now());
  return now - scheduler.Now().time_since_epoch();
}

}  // namespace canfleet
