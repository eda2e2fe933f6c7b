#pragma once
/// @file The delay before a crashed node process is started again: doubling from the policy's
/// first delay up to a ceiling, and back to the first delay once the process had run stably for
/// a while, so that a node that crashed five times an hour ago is not restarted 10 s late forever.

#include <algorithm>
#include <chrono>

namespace canfleet::fleet {

class RestartBackoff {
 public:
  /// A process that ran this long before it ended counts as stable: its crash is a new episode.
  static constexpr std::chrono::milliseconds kStablePeriod{60'000};
  static constexpr std::chrono::milliseconds kMaxDelay{10'000};

  explicit RestartBackoff(std::chrono::milliseconds first) : first_(first), next_(first) {}

  /// The delay before the next start of a process that ran for `ran` before it ended.
  template <class Duration>
  std::chrono::milliseconds After(Duration ran) {
    if (ran >= kStablePeriod) next_ = first_;
    const auto delay = next_;
    next_ = std::min(kMaxDelay, std::max(first_, next_ * 2));
    return delay;
  }

 private:
  std::chrono::milliseconds first_;
  std::chrono::milliseconds next_;
};

}  // namespace canfleet::fleet
