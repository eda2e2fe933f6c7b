#include "node/devices/encoder_dual_valve/quadrature.hpp"

#include <chrono>
#include <cmath>

namespace canfleet::devices::encoder {

double Shaft::PositionAt(TimePoint now) const {
  const double seconds = std::chrono::duration<double>(now - since_).count();
  return base_ + velocity_ * seconds;
}

std::int64_t Shaft::EdgesAt(TimePoint now) const {
  return static_cast<std::int64_t>(std::floor(PositionAt(now) + 0.5));
}

void Shaft::SetVelocity(TimePoint now, double edges_per_second) {
  base_ = PositionAt(now);
  since_ = now;
  velocity_ = edges_per_second;
}

void Shaft::MoveTo(TimePoint now, double position) {
  base_ = position;
  since_ = now;
}

std::int32_t StepCounter::Steps(std::int64_t edges) const {
  // Two's-complement wrap of the 32-bit register (done on the unsigned value: no signed overflow).
  const auto wrapped = static_cast<std::uint32_t>(static_cast<std::uint64_t>(edges - zero_));
  return static_cast<std::int32_t>(wrapped);
}

double ScaledCount(std::int32_t steps, const QuadratureParams& params) {
  const double signed_steps = params.inverted ? -static_cast<double>(steps) : static_cast<double>(steps);
  return params.scaler * (signed_steps + static_cast<double>(params.offset));
}

double SpeedRpm(double edges_per_second, const QuadratureParams& params) {
  if (params.pulses_per_rev < 1) return 0.0;
  return std::abs(edges_per_second) * 60.0 / (4.0 * static_cast<double>(params.pulses_per_rev));
}

double EdgesPerSecond(double rpm, double pulses_per_rev) {
  return rpm / 60.0 * 4.0 * pulses_per_rev;
}

}  // namespace canfleet::devices::encoder
