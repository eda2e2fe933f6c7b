#include "node/devices/blocks/lookup_table.hpp"

#include <algorithm>
#include <cmath>

namespace canfleet::devices::blocks {
namespace {

// The lookup of §1.7.3 over n points given by accessors, shared by the data response (X = the
// source value) and the time response (X = ms into the profile), so neither copies the table.
template <typename XAt>
double Lookup(std::span<const LutPoint> points, std::size_t n, XAt x_at, double x) {
  if (n == 0) return 0.0;
  if (x <= x_at(0)) return points[0].y;
  for (std::size_t k = 1; k < n; ++k) {
    const double x_hi = x_at(k);
    if (x > x_hi) continue;
    if (points[k].response == PointResponse::kJumpTo) return points[k].y;
    const double x_lo = x_at(k - 1);
    if (x_hi <= x_lo) return points[k].y;  // zero-width segment: already at its end
    return points[k - 1].y + (points[k].y - points[k - 1].y) * (x - x_lo) / (x_hi - x_lo);
  }
  return points[n - 1].y;  // held at the last used point
}

// Start time (ms) of each used point of a time response.
class TimeAxis {
 public:
  TimeAxis(std::span<const LutPoint> points, std::size_t n, TimeAxisMode mode) : points_(points), n_(n) {
    std::int64_t t = 0;
    for (std::size_t k = 0; k < n_ && k < times_.size(); ++k) {
      const auto x = static_cast<std::int64_t>(std::llround(std::max(0.0, points[k].x)));
      if (k == 0) {
        t = 0;  // point 1 is (0 ms, Y1) whatever is stored (§1.7.4 "automatically set to [0,0]")
      } else if (mode == TimeAxisMode::kIntervals) {
        t += x;
      } else {
        t = std::max(t, x);
      }
      times_[k] = t;
    }
    if (n_ > times_.size()) n_ = times_.size();
  }

  std::size_t size() const { return n_; }
  std::int64_t At(std::size_t k) const { return times_[k]; }
  std::int64_t Total() const { return n_ == 0 ? 0 : times_[n_ - 1]; }
  double ValueAt(std::int64_t t) const {
    return Lookup(
        points_, n_, [this](std::size_t k) { return static_cast<double>(times_[k]); },
        static_cast<double>(t));
  }

 private:
  std::span<const LutPoint> points_;
  std::size_t n_;
  // 11 points in every product; more are not read.
  std::array<std::int64_t, 32> times_{};
};

}  // namespace

LookupTableProfile ValveLookupTableProfile() {
  return LookupTableProfile{};
}

LookupTableProfile DataLoggerLookupTableProfile() {
  return LookupTableProfile{};
}

LookupTableProfile EncoderLookupTableProfile() {
  LookupTableProfile p;
  p.y_range = YRangeRule::kUsedPointsOnly;
  p.max_time_interval = std::chrono::milliseconds{60'000};
  p.response_codes = {PointResponse::kRampTo, PointResponse::kJumpTo, std::nullopt};
  return p;
}

LookupTableParams DefaultLookupTableParams(const LookupTableProfile& profile) {
  LookupTableParams params;
  for (std::size_t k = 0; k < profile.points; ++k) {
    const double v = 10.0 * static_cast<double>(k);
    params.points.push_back(LutPoint{v, v, PointResponse::kRampTo});
  }
  return params;
}

std::size_t UsedPointCount(std::span<const LutPoint> points) {
  for (std::size_t k = 1; k < points.size(); ++k) {
    if (points[k].response == PointResponse::kIgnore) return k;
  }
  return points.size();
}

bool XAxisNonDecreasing(std::span<const LutPoint> points) {
  const std::size_t n = UsedPointCount(points);
  for (std::size_t k = 1; k < n; ++k) {
    if (points[k].x < points[k - 1].x) return false;
  }
  return true;
}

std::pair<double, double> OutputRange(std::span<const LutPoint> points, YRangeRule rule) {
  const std::size_t n = rule == YRangeRule::kUsedPointsOnly ? UsedPointCount(points) : points.size();
  if (n == 0) return {0.0, 100.0};
  double lo = points[0].y;
  double hi = points[0].y;
  for (std::size_t k = 1; k < n; ++k) {
    lo = std::min(lo, points[k].y);
    hi = std::max(hi, points[k].y);
  }
  switch (rule) {
    case YRangeRule::kPercentUnlessOutside:
      if (lo >= 0.0 && hi <= 100.0) return {0.0, 100.0};
      return {lo, hi};
    case YRangeRule::kWidenedToPercent:
      return {std::min(0.0, lo), std::max(100.0, hi)};
    case YRangeRule::kUsedPointsOnly:
      return {lo, hi};
  }
  return {lo, hi};
}

double EvaluateData(std::span<const LutPoint> points, double x) {
  return Lookup(
      points, UsedPointCount(points), [points](std::size_t k) { return points[k].x; }, x);
}

const Signal& LookupTable::Update(const LookupTableParams& params, const Signal& x,
                                  std::chrono::milliseconds elapsed) {
  const std::span<const LutPoint> points(params.points);
  const auto [lo, hi] = OutputRange(points, profile_.y_range);
  Signal out;
  out.min = lo;
  out.max = hi;
  out.decimal_digits = params.y_digits;
  out.error = x.error;
  out.available = x.available;
  next_change_.reset();

  if (params.x_axis_type == XAxisType::kData) {
    running_ = false;
    time_ = std::chrono::milliseconds{0};
    if (x.available) out.value = std::round(EvaluateData(points, x.value));
    output_ = out;
    return output_;
  }

  const bool on = x.available && !x.error && x.value != 0.0;
  if (!on) {
    running_ = false;
    time_ = std::chrono::milliseconds{0};
    output_ = out;  // "When the control input is OFF, the output is always at zero."
    return output_;
  }

  const TimeAxis axis(points, UsedPointCount(points), profile_.time_mode);
  const std::int64_t total = axis.Total();
  if (!running_) {
    running_ = true;  // starts at (X1, Y1) on the tick that sees ON
    time_ = std::chrono::milliseconds{0};
  } else {
    time_ += elapsed;
    if (time_.count() >= total) {
      if (params.auto_repeat && total > 0) {
        time_ = std::chrono::milliseconds{time_.count() % total};
      } else {
        time_ = std::chrono::milliseconds{total};
      }
    }
  }
  const std::int64_t t = time_.count();
  out.value = std::round(axis.ValueAt(t));
  output_ = out;

  if (total == 0 || (!params.auto_repeat && t >= total)) return output_;  // holding
  for (std::size_t k = 1; k < axis.size(); ++k) {
    if (t >= axis.At(k)) continue;
    const LutPoint& p = points[k];
    const bool ramping = p.response != PointResponse::kJumpTo && p.y != points[k - 1].y;
    if (ramping || std::round(p.y) != out.value) {
      next_change_ = std::chrono::milliseconds{0};
    } else {
      next_change_ = std::chrono::milliseconds{axis.At(k) - t};
    }
    break;
  }
  return output_;
}

void LookupTable::Reset() {
  output_ = Signal::NotAvailable();
  running_ = false;
  time_ = std::chrono::milliseconds{0};
  next_change_.reset();
}

}  // namespace canfleet::devices::blocks
