#pragma once
/// @file The quadrature encoder (AX023241 1.2, Figure 2, 3410h-3413h): the simulated shaft and the
/// controller's decoder, as events in simulated time (design decision 10): nothing simulates edges.
///
/// Shaft. Its position is counted in quadrature edges: one encoder pulse per channel is four edges
/// (QA rises, QB rises, QA falls, QB falls when QA leads QB = forward). The position moves at a
/// piecewise-constant velocity; PositionAt(t) = position at the last change + velocity x elapsed.
/// Edges sit half-way between whole positions, so the edges passed since power-on are the position
/// rounded to the nearest whole number (ties upwards), the same in both directions.
///
/// Decoder ("Edge (step) count", Table 3): every edge of QA and QB is one step (x4 decoding; the
/// manual's Figure 2 is lost, and its processor, a TMS320F2806x, counts this way in the eQEP's
/// quadrature-count mode). Forward edges count up, reverse edges down. The step counter is a
/// 32-bit two's-complement register (eQEP QPOSCNT) that wraps from 7FFFFFFFh to 80000000h and
/// back; it is zeroed at power-on/reset node and when 6110h or 2100h is written. From it:
///   count     = 3410h x (s x steps + 3412h), s = -1 when 3411h = 1 (direction inverted)
///   direction = 1 while the last movement counted up, 0 after one counting down (0 at power-on)
///   speed     = |steps per second| x 60 / (4 x 3413h) rpm (3413h = pulses per revolution)
/// The count object (7100h, INTEGER16) holds the count rounded and saturated at -32768..32767
/// (the register keeps counting; the value comes back once the count is in range again).

#include <cstdint>

#include "clock/scheduler.hpp"

namespace canfleet::devices::encoder {

class Shaft {
 public:
  /// Position in edges at `now` (fractional).
  double PositionAt(TimePoint now) const;
  /// Whole edges passed since power-on at `now` (signed).
  std::int64_t EdgesAt(TimePoint now) const;
  /// Edges per second, signed (+ = forward).
  double Velocity() const { return velocity_; }
  /// The velocity from `now` on (the position up to now is kept).
  void SetVelocity(TimePoint now, double edges_per_second);
  /// Moves the shaft to `position` edges at `now` (a jump: every edge in between is passed).
  void MoveTo(TimePoint now, double position);

 private:
  TimePoint since_{};
  double base_ = 0.0;
  double velocity_ = 0.0;
};

/// The decoder's 32-bit step counter.
class StepCounter {
 public:
  /// Zeroes the counter with the shaft at `edges`.
  void Zero(std::int64_t edges) { zero_ = edges; }
  /// The register with the shaft at `edges`: steps since Zero(), wrapped to 32 bits.
  std::int32_t Steps(std::int64_t edges) const;

 private:
  std::int64_t zero_ = 0;
};

/// 3410h-3413h as read from the dictionary.
struct QuadratureParams {
  double scaler = 1.0;              ///< 3410h
  bool inverted = false;            ///< 3411h = 1
  std::int64_t offset = 0;          ///< 3412h, steps
  std::int64_t pulses_per_rev = 4;  ///< 3413h
};

/// The scaled count (unrounded, unsaturated).
double ScaledCount(std::int32_t steps, const QuadratureParams& params);
/// The speed in rpm for `edges_per_second` (0 when 3413h < 1).
double SpeedRpm(double edges_per_second, const QuadratureParams& params);
/// Edges per second of a shaft turning at `rpm` with an encoder of `pulses_per_rev`.
double EdgesPerSecond(double rpm, double pulses_per_rev);

}  // namespace canfleet::devices::encoder
