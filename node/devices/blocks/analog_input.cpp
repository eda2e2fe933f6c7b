#include "node/devices/blocks/analog_input.hpp"

#include <cmath>

namespace canfleet::devices::blocks {
namespace {

// "This filter is called every 1ms." (valve §1.3)
constexpr std::chrono::milliseconds kFilterCall{1};

}  // namespace

double ScaleToProcessValue(const AnalogInputParams& params, double fv) {
  const double dfv = params.scaling2_fv - params.scaling1_fv;
  if (dfv == 0.0) return fv;
  return params.scaling1_pv + (fv - params.scaling1_fv) * (params.scaling2_pv - params.scaling1_pv) / dfv;
}

void AnalogInput::Tick(std::chrono::milliseconds elapsed, const AnalogInputParams& params, double measured) {
  const double in = measured * PowerOfTen(params.fv_digits);
  std::chrono::milliseconds remaining = elapsed;
  while (remaining >= kFilterCall) {
    if (filter_.Settled(params.filter, in)) {
      // The field value is final: the span monitor only has time left to count, in one go (a
      // flag the parameters set now counts from the start of that time).
      span_.Update(params.span, fv_, std::chrono::milliseconds{0});
      span_.Update(params.span, fv_, remaining);
      remaining = std::chrono::milliseconds{0};
      break;
    }
    filter_.Step(params.filter, in);
    fv_ = std::round(filter_.Value());
    span_.Update(params.span, fv_, kFilterCall);
    remaining -= kFilterCall;
  }
  if (elapsed < kFilterCall) span_.Update(params.span, fv_, elapsed);  // parameters may have changed
  settled_ = filter_.Settled(params.filter, in);
  UpdateProcessValue(params);
}

void AnalogInput::UpdateProcessValue(const AnalogInputParams& params) {
  pv_ = std::round(ScaleToProcessValue(params, fv_));
}

Signal AnalogInput::AsSource(const AnalogInputParams& params) const {
  Signal s;
  s.value = fv_;
  s.min = params.scaling1_fv;
  s.max = params.scaling2_fv;
  s.decimal_digits = params.fv_digits;
  s.error = span_.Faulted();
  return s;
}

void AnalogInput::Reset() {
  filter_.Reset();
  span_.Reset();
  fv_ = 0.0;
  pv_ = 0.0;
  settled_ = false;
}

}  // namespace canfleet::devices::blocks
