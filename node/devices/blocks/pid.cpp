#include "node/devices/blocks/pid.hpp"

#include <algorithm>
#include <cmath>

namespace canfleet::devices::blocks {
namespace {

// Target normalised as §1.6 says: a target without limits (a constant) uses the feedback's.
double TargetPercent(const Signal& target, const Signal& feedback) {
  if (!target.has_range && feedback.has_range)
    return Signal::PercentOf(target.value, feedback.min, feedback.max);
  return target.ToPercent();
}

bool PushPull(PidResponse r) {
  return r == PidResponse::kOnWhenOverTarget || r == PidResponse::kOnWhenBelowTarget;
}

}  // namespace

PidProfile ValvePidProfile() {
  return PidProfile{};
}

PidProfile EncoderPidProfile() {
  PidProfile p;
  p.gain_scales_integral_and_derivative = false;
  p.formula_period = std::chrono::duration<double>{0.001};
  p.response_codes = {PidResponse::kSingleOutput, PidResponse::kSetpointControl,
                      PidResponse::kOnWhenOverTarget, PidResponse::kOnWhenBelowTarget};
  return p;
}

PidGains ComputePidGains(const PidParams& params, const PidProfile& profile) {
  const double t = profile.formula_period ? profile.formula_period->count()
                                          : std::chrono::duration<double>(params.cycle).count();
  const double ti = std::chrono::duration<double>(params.ti).count();
  const double td = std::chrono::duration<double>(params.td).count();
  const double g = profile.gain_scales_integral_and_derivative ? params.gain : 1.0;
  PidGains gains;
  gains.p = params.gain;
  gains.i = ti == 0.0 ? 0.0 : g * params.ki * t / ti;  // "If Ti is zero, I_Gain = 0"
  gains.d = t == 0.0 ? 0.0 : g * params.kd * td / t;
  return gains;
}

const Signal& Pid::Tick(std::chrono::milliseconds elapsed, const PidParams& params, const Signal& target,
                        const Signal& feedback) {
  const std::chrono::milliseconds cycle = std::max(params.cycle, std::chrono::milliseconds{1});
  since_step_ += elapsed;
  while (since_step_ >= cycle) {
    since_step_ -= cycle;
    Step(params, target, feedback);
  }
  return output_;
}

const Signal& Pid::Step(const PidParams& params, const Signal& target, const Signal& feedback) {
  // "Unless both the target and feedback inputs have legitimate control sources selected, the
  // PID loop is disabled." (valve §1.6)
  if (!target.available || !feedback.available) {
    Reset();
    return output_;
  }
  enabled_ = true;
  if (target.error || feedback.error) {
    output_.error = true;  // hold the last output; a consumer applies its own fault mode
    return output_;
  }

  double e = TargetPercent(target, feedback) - feedback.ToPercent();
  if (std::abs(e) < params.tolerance_percent) e = 0.0;
  const PidGains g = ComputePidGains(params, profile_);
  const double lo = PushPull(params.response) ? -100.0 : 0.0;
  const double hi = 100.0;

  const double de = e - previous_error_;
  const double pd = e * g.p + de * g.d;
  double sum = error_sum_ + e;
  double out = pd + sum * g.i;
  // Anti-windup: past a limit, with E pushing further that way, S only grows as far as it takes
  // the output to the limit (never less than it was: P and D alone may already be past it).
  const double limit = out > hi ? hi : lo;
  if ((out > hi || out < lo) && (out - limit) * e * g.i > 0.0) {
    sum = std::clamp((limit - pd) / g.i, std::min(error_sum_, error_sum_ + e),
                     std::max(error_sum_, error_sum_ + e));
    out = pd + sum * g.i;
  }
  out = std::clamp(out, lo, hi);

  settled_ = e == 0.0 && previous_error_ == 0.0;
  error_sum_ = sum;
  previous_error_ = e;
  error_ = e;
  switch (params.response) {
    case PidResponse::kOnWhenOverTarget:
      output_percent_ = std::max(0.0, -out);
      break;
    case PidResponse::kOnWhenBelowTarget:
    case PidResponse::kSingleOutput:
    case PidResponse::kSetpointControl:
      output_percent_ = std::max(0.0, out);
      break;
  }
  output_ = Signal::Percent(output_percent_);
  return output_;
}

bool Pid::Busy() const {
  return enabled_ && !settled_;
}

std::chrono::milliseconds Pid::NextStepAfter(const PidParams& params) const {
  const std::chrono::milliseconds cycle = std::max(params.cycle, std::chrono::milliseconds{1});
  return cycle - since_step_;
}

void Pid::Reset() {
  output_ = Signal::Percent(0.0);
  output_percent_ = 0.0;
  error_ = 0.0;
  previous_error_ = 0.0;
  error_sum_ = 0.0;
  enabled_ = false;
  settled_ = false;
}

}  // namespace canfleet::devices::blocks
