#include "node/devices/valve_12in12out/output_math.hpp"

#include <algorithm>
#include <cmath>

namespace canfleet::devices::valve {

double FieldValueOf(double pv, const OutputScaling& s, std::uint8_t response) {
  if (response == 1 && pv < s.s1_pv) return 0.0;
  if (response == 2 && pv > s.s2_pv) return 0.0;
  if (s.s2_pv <= s.s1_pv) return pv >= s.s2_pv ? s.s2_fv : s.s1_fv;
  if (pv <= s.s1_pv) return s.s1_fv;
  if (pv >= s.s2_pv) return s.s2_fv;
  return s.s1_fv + (pv - s.s1_pv) * (s.s2_fv - s.s1_fv) / (s.s2_pv - s.s1_pv);
}

bool LogicStateOf(double pv, const OutputScaling& s) {
  if (s.s2_pv <= s.s1_pv) return pv >= s.s2_pv && pv != 0.0;
  return pv >= (s.s1_pv + s.s2_pv) / 2.0;
}

double RampStep(double present, double target, const OutputScaling& s, std::int64_t ramp_up_ms,
                std::int64_t ramp_down_ms, std::chrono::milliseconds elapsed) {
  if (present == target) return target;
  const bool up = target > present;
  const std::int64_t ramp_ms = up ? ramp_up_ms : ramp_down_ms;
  const double span = std::abs(s.s2_fv - s.s1_fv);
  if (ramp_ms <= 0 || span == 0.0) return target;
  const double step = span / static_cast<double>(ramp_ms) * static_cast<double>(elapsed.count());
  return up ? std::min(target, present + step) : std::max(target, present - step);
}

void FeedbackAverager::Add(double value, std::int64_t duration_ms, std::int64_t samples) {
  const std::int64_t n = std::clamp<std::int64_t>(samples, 1, 100);
  if (count_ >= n) {  // 2371h lowered mid-window: that window is complete
    value_ = std::round(sum_ / static_cast<double>(count_));
    sum_ = 0;
    count_ = 0;
  }
  while (duration_ms > 0) {
    const std::int64_t take = std::min(n - count_, duration_ms);
    sum_ += value * static_cast<double>(take);
    count_ += take;
    duration_ms -= take;
    if (count_ < n) break;
    value_ = std::round(sum_ / static_cast<double>(n));
    sum_ = 0;
    count_ = 0;
    if (duration_ms >= n) {
      // Whole windows of the same value: their average is the value (an idle stretch costs nothing).
      value_ = std::round(value);
      count_ = duration_ms % n;
      sum_ = value * static_cast<double>(count_);
      duration_ms = 0;
    }
  }
}

std::int64_t FeedbackAverager::UntilChange(double sample, std::int64_t samples) const {
  const std::int64_t n = std::clamp<std::int64_t>(samples, 1, 100);
  const double expected = sample * static_cast<double>(count_);
  const bool window_is_sample = std::abs(sum_ - expected) <= 1e-9 * std::max(1.0, std::abs(expected));
  if (value_ == std::round(sample) && window_is_sample) return 0;
  return std::max<std::int64_t>(1, n - count_);
}

void FeedbackAverager::Reset() {
  value_ = 0;
  sum_ = 0;
  count_ = 0;
}

}  // namespace canfleet::devices::valve
