#pragma once
/// @file The lookup table block (valve UMAX020411A §1.7, encoder AX023241 §1.6, logger
/// UMAX181001 §1.5).
///
/// Data response (X-axis type 0): the X source's raw value is looked up in points
/// (X1,Y1)..(Xn,Yn) (n = 11 in all three products: "up to 10 slopes", valve §1.7):
/// - x <= X1 gives Y1; above the last used point the output holds that point's Y.
/// - Point N "ramp to": linear from (X[N-1],Y[N-1]) to (X[N],Y[N]); "jump to": any x in
///   (X[N-1], X[N]] gives Y[N] (§1.7.3).
/// - "Ignore" at N cuts the table: points N..n are not used, x > X[N-1] gives Y[N-1]. Point 1
///   cannot be ignored (its response is never looked at; in the valve its sub-index is the X-axis
///   type).
/// Time response (X-axis type 1, §1.7.4): the X source is read as digital (ON = available, not
/// in error, value != 0). OFF: output 0. OFF->ON: the profile starts at (X1,Y1) = 0 ms on that
/// tick, and every later tick advances it by the tick's period. At the end (last point or an
/// ignore) the output holds the last Y, or with auto-repeat restarts at point 1. X values are
/// durations in ms: by default the interval between a point and the previous one ("the interval
/// time between each point", all three manuals), optionally absolute times (TimeAxisMode).
/// Output range seen by consumers (§1.7.2, Table 17; differs per product, YRangeRule).
///
/// Tick order and loop rule: see signal.hpp (inputs -> math -> LUT -> logic -> PID -> outputs; a
/// block reading itself or a later block sees the previous tick).

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "node/devices/blocks/signal.hpp"

namespace canfleet::devices::blocks {

enum class XAxisType : std::uint8_t { kData, kTime };
enum class PointResponse : std::uint8_t { kIgnore, kRampTo, kJumpTo };

/// Which limits a table reports to the blocks it feeds.
enum class YRangeRule : std::uint8_t {
  /// Valve/logger §1.7.2 text: 0..100 while every Y (ignored points included) is within 0..100,
  /// else the lowest..highest Y.
  kPercentUnlessOutside,
  /// Valve/logger Table 17: min(0, lowest Y)..max(100, highest Y), ignored points included.
  kWidenedToPercent,
  /// Encoder §1.6.2: lowest..highest Y of the points that are not ignored.
  kUsedPointsOnly,
};

/// How the X values of a time response are read.
enum class TimeAxisMode : std::uint8_t {
  kIntervals,  ///< X[N] = ms from point N-1 to point N
  kAbsolute,   ///< X[N] = ms from the start of the profile
};

struct LutPoint {
  double x = 0.0;
  double y = 0.0;
  PointResponse response = PointResponse::kRampTo;
};

/// The per-product facts of the block.
struct LookupTableProfile {
  std::size_t points = 11;
  YRangeRule y_range = YRangeRule::kPercentUnlessOutside;
  TimeAxisMode time_mode = TimeAxisMode::kIntervals;
  /// Largest X of a time point (valve/logger 86 400 000 ms, encoder 60 000 ms).
  std::chrono::milliseconds max_time_interval{86'400'000};
  /// Point response object value -> response (nullopt = value not allowed).
  std::array<std::optional<PointResponse>, 3> response_codes{PointResponse::kIgnore, PointResponse::kRampTo,
                                                             PointResponse::kJumpTo};

  std::optional<PointResponse> DecodeResponse(std::uint8_t code) const {
    return code < response_codes.size() ? response_codes[code] : std::nullopt;
  }
};

/// Valve §1.7 / logger §1.5: 11 points; 3yz5h sub 1 = X type, sub 2-11: 0 ignore, 1 ramp, 2 jump.
LookupTableProfile ValveLookupTableProfile();
LookupTableProfile DataLoggerLookupTableProfile();
/// Encoder §1.6, §C3-1.4.42: 11 points (X0..X10); 30x5h sub N = transition N-1..N: 0 ramp,
/// 1 jump (no object value for ignore); Y range of used points; time points 1..60 000 ms.
LookupTableProfile EncoderLookupTableProfile();

/// The block's configuration, as read from its objects.
struct LookupTableParams {
  XAxisType x_axis_type = XAxisType::kData;
  bool auto_repeat = false;
  std::vector<LutPoint> points;
  /// 3yz4h: decimals of Y and so of the output.
  std::uint8_t y_digits = 0;
};

/// Default table: X and Y 0, 10, ..., 100, all ramp-to (valve §1.7.3, §3.4.68-69).
LookupTableParams DefaultLookupTableParams(const LookupTableProfile& profile);

/// Number of points in use: up to (not including) the first ignored point after point 1.
std::size_t UsedPointCount(std::span<const LutPoint> points);
/// Valve §1.7.1: X1 <= X2 <= ... over the used points (for SDO validation of 3yz6h).
bool XAxisNonDecreasing(std::span<const LutPoint> points);
/// The limits consumers see (Table 17 / §1.7.2), per `rule`.
std::pair<double, double> OutputRange(std::span<const LutPoint> points, YRangeRule rule);
/// The data response for input `x` (no rounding).
double EvaluateData(std::span<const LutPoint> points, double x);

class LookupTable {
 public:
  explicit LookupTable(LookupTableProfile profile = ValveLookupTableProfile()) : profile_(profile) {}

  /// Evaluates one tick. `x` is the X-axis source (NotAvailable() if 3yz0h = 0), `elapsed` the
  /// time since the previous Update (used by the time response only).
  const Signal& Update(const LookupTableParams& params, const Signal& x, std::chrono::milliseconds elapsed);

  /// The output as of the last Update: value = Y rounded like 3yz8h (INTEGER16), limits per
  /// the profile's YRangeRule, error = the X source's error, available = the X source is set.
  const Signal& Output() const { return output_; }

  /// Time response only: how long the output stays as it is while the input stays ON (0 = it
  /// is ramping and changes on the next tick); nullopt = it will not change by itself (data
  /// response, input OFF, or holding the end of the profile).
  std::optional<std::chrono::milliseconds> NextChangeAfter() const { return next_change_; }
  /// Whether further ticks with the same input can change the output.
  bool Busy() const { return next_change_.has_value(); }

  /// Time into the running profile (0 when stopped).
  std::chrono::milliseconds ProfileTime() const { return time_; }

  /// Power-up state: stopped, output 0.
  void Reset();

  const LookupTableProfile& profile() const { return profile_; }

 private:
  LookupTableProfile profile_;
  Signal output_ = Signal::NotAvailable();
  bool running_ = false;
  std::chrono::milliseconds time_{0};
  std::optional<std::chrono::milliseconds> next_change_;
};

}  // namespace canfleet::devices::blocks
