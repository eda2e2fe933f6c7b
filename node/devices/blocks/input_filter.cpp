#include "node/devices/blocks/input_filter.hpp"

#include <algorithm>
#include <cmath>

namespace canfleet::devices::blocks {
namespace {

constexpr double kSnap = 0.001;

std::uint32_t Constant(const FilterParams& p) {
  return std::max<std::uint32_t>(p.constant, 1u);
}

// Arithmetic shift right of a signed value (floor division by 2^p), as the firmware's ">> P".
std::int64_t ShiftRight(std::int64_t v, std::uint8_t p) {
  return v >> std::min<std::uint8_t>(p, 62);
}

}  // namespace

std::optional<FilterType> DecodeFilterType(std::uint8_t code, bool third_order) {
  const std::uint8_t last = third_order ? 3 : 2;
  if (code > last) return std::nullopt;
  return static_cast<FilterType>(code);
}

std::int64_t InputFilter::ThirdOrderNext(const ThirdOrderCoefficients& c, std::int64_t in) const {
  std::int64_t acc = c.input[0] * in;
  for (std::size_t i = 0; i < 3; ++i) {
    acc += c.input[i + 1] * in_history_[i];
    acc += c.output[i] * out_history_[i];
  }
  return ShiftRight(acc, c.power);
}

void InputFilter::Step(const FilterParams& params, double in) {
  switch (params.type) {
    case FilterType::kNone:
      value_ = in;
      return;
    case FilterType::kMovingAverage:
      value_ += (in - value_) / static_cast<double>(Constant(params));
      if (std::abs(in - value_) < kSnap) value_ = in;
      return;
    case FilterType::kRepeatingAverage:
      sum_ += in;
      if (++count_ >= Constant(params)) {
        value_ = sum_ / static_cast<double>(count_);
        sum_ = 0.0;
        count_ = 0;
      }
      return;
    case FilterType::kThirdOrderLowPass: {
      // "The value of object 61A1h determines how often the filter is called (in ms)."
      if (++count_ < Constant(params)) return;
      count_ = 0;
      const std::int64_t x = std::llround(in);
      const std::int64_t v = ThirdOrderNext(params.third_order, x);
      in_history_ = {x, in_history_[0], in_history_[1]};
      out_history_ = {v, out_history_[0], out_history_[1]};
      value_ = static_cast<double>(v);
      return;
    }
  }
}

bool InputFilter::Settled(const FilterParams& params, double in) const {
  switch (params.type) {
    case FilterType::kNone:
    case FilterType::kMovingAverage:
      return value_ == in;
    case FilterType::kRepeatingAverage:
      return count_ == 0 && std::abs(value_ - in) <= 1e-9 * std::max(1.0, std::abs(in));
    case FilterType::kThirdOrderLowPass: {
      const std::int64_t x = std::llround(in);
      const bool inputs_steady = in_history_[0] == x && in_history_[1] == x && in_history_[2] == x;
      const bool outputs_steady = out_history_[0] == out_history_[1] && out_history_[1] == out_history_[2];
      return inputs_steady && outputs_steady && ThirdOrderNext(params.third_order, x) == out_history_[0];
    }
  }
  return true;
}

void InputFilter::Reset(double value) {
  value_ = value;
  sum_ = 0.0;
  count_ = 0;
  const std::int64_t v = std::llround(value);
  in_history_ = {v, v, v};
  out_history_ = {v, v, v};
}

}  // namespace canfleet::devices::blocks
