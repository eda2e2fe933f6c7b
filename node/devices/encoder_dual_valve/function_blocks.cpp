#include "node/devices/encoder_dual_valve/function_blocks.hpp"

#include <algorithm>
#include <cmath>

#include "node/devices/od_ref.hpp"

namespace canfleet::devices::encoder {
namespace {

using blocks::Signal;

bool Same(const Signal& a, const Signal& b) {
  return a.value == b.value && a.min == b.min && a.max == b.max && a.error == b.error &&
         a.available == b.available && a.has_range == b.has_range;
}

}  // namespace

FunctionBlocks::FunctionBlocks(canopen::ObjectDictionary& od)
    : od_(od),
      lut_{blocks::LookupTable(blocks::EncoderLookupTableProfile()),
           blocks::LookupTable(blocks::EncoderLookupTableProfile())},
      pid_(blocks::EncoderPidProfile()) {
  for (int m = 0; m < kMathBlocks; ++m)
    math_.emplace_back(blocks::EncoderMathProfile(), static_cast<std::uint8_t>(m + 1));
}

blocks::MathBlockParams FunctionBlocks::MathParams(int block) const {
  const auto b = static_cast<std::uint8_t>(block);
  blocks::MathBlockParams p = blocks::DefaultMathBlockParams(blocks::EncoderMathProfile());
  p.enabled = od_.GetUnsigned(kMathEnable, b) != 0;
  for (int i = 0; i < kMathInputs; ++i) {
    const auto sub = static_cast<std::uint8_t>(i + 1);
    blocks::MathInputParams& in = p.inputs[static_cast<std::size_t>(i)];
    in.source.source = static_cast<std::uint8_t>(od_.GetUnsigned(MathIndex(block, kMathSource), sub));
    in.source.number = static_cast<std::uint8_t>(od_.GetUnsigned(MathIndex(block, kMathNumber), sub));
    in.decimal_digits = static_cast<std::uint8_t>(od_.GetUnsigned(MathIndex(block, kMathDigits), sub));
    in.scaling1 = static_cast<double>(od_.GetSigned(MathIndex(block, kMathScaling1), sub));
    in.scaling2 = static_cast<double>(od_.GetSigned(MathIndex(block, kMathScaling2), sub));
    in.gain = static_cast<double>(od_.GetSigned(MathIndex(block, kMathGain), sub)) / 100.0;
  }
  for (int k = 0; k < kMathOperators; ++k)
    p.operators[static_cast<std::size_t>(k)] = static_cast<std::uint8_t>(
        od_.GetUnsigned(MathIndex(block, kMathOperator), static_cast<std::uint8_t>(k + 1)));
  p.output_scaling1 = static_cast<double>(od_.GetSigned(kMathOutScaling1, b));
  p.output_scaling2 = static_cast<double>(od_.GetSigned(kMathOutScaling2, b));
  p.output_digits = static_cast<std::uint8_t>(od_.GetUnsigned(kMathOutDigits, b));
  return p;
}

void FunctionBlocks::UpdateMath(const blocks::ControlSources& sources) {
  for (int m = 0; m < kMathBlocks; ++m) {
    const Signal& out = math_[static_cast<std::size_t>(m)].Update(MathParams(m + 1), sources);
    OdRef(od_, kMathOutput, static_cast<std::uint8_t>(m + 1)).SetNumber(out.value);
  }
}

blocks::LookupTableParams FunctionBlocks::LutParams(int table) const {
  const blocks::LookupTableProfile profile = blocks::EncoderLookupTableProfile();
  blocks::LookupTableParams p;
  p.x_axis_type = blocks::XAxisType::kData;
  p.auto_repeat = od_.GetUnsigned(LutIndex(table, kLutAutoRepeat), 0) != 0;
  p.y_digits = static_cast<std::uint8_t>(od_.GetUnsigned(LutIndex(table, kLutYDigits), 0));
  for (int k = 0; k < kLutPoints; ++k) {
    const auto sub = static_cast<std::uint8_t>(k + 1);
    blocks::LutPoint point;
    point.x = static_cast<double>(od_.GetSigned(LutIndex(table, kLutX), sub));
    point.y = static_cast<double>(od_.GetSigned(LutIndex(table, kLutY), sub));
    if (k > 0) {
      const auto code = static_cast<std::uint8_t>(
          od_.GetUnsigned(LutIndex(table, kLutResponse), static_cast<std::uint8_t>(k)));
      point.response = profile.DecodeResponse(code).value_or(blocks::PointResponse::kRampTo);
    }
    p.points.push_back(point);
  }
  return p;
}

void FunctionBlocks::UpdateLookupTables(const blocks::ControlSources& sources) {
  for (int t = 0; t < kLookupTables; ++t) {
    const int table = t + 1;
    const blocks::SourceRef ref{static_cast<std::uint8_t>(od_.GetUnsigned(LutIndex(table, kLutSource), 0)),
                                static_cast<std::uint8_t>(od_.GetUnsigned(LutIndex(table, kLutNumber), 0))};
    Signal x = sources.Resolve(ref);
    const auto x_digits = static_cast<std::uint8_t>(od_.GetUnsigned(LutIndex(table, kLutXDigits), 0));
    x.value = x.value / blocks::PowerOfTen(x.decimal_digits) * blocks::PowerOfTen(x_digits);
    const Signal& out = lut_[static_cast<std::size_t>(t)].Update(LutParams(table), x, Ms{0});
    OdRef(od_, LutIndex(table, kLutOutput), 0).SetNumber(out.value);
  }
}

blocks::PidParams FunctionBlocks::PidParameters() const {
  blocks::PidParams p;
  const double time_scale =
      1000.0 / blocks::PowerOfTen(static_cast<std::uint8_t>(od_.GetUnsigned(kPidTimingDigits, 0)));
  p.gain = static_cast<double>(od_.GetSigned(kPidProportionalBand, 0)) / 10.0;
  p.ki = static_cast<double>(od_.GetSigned(kPidIntegralGain, 0)) / 10.0;
  p.kd = static_cast<double>(od_.GetSigned(kPidDerivativeGain, 0)) / 10.0;
  p.tolerance_percent = static_cast<double>(od_.GetSigned(kPidTolerance, 0)) / 10.0;
  p.ti = std::chrono::duration<double, std::milli>(static_cast<double>(od_.GetSigned(kPidIntegralTime, 0)) *
                                                   time_scale);
  p.td = std::chrono::duration<double, std::milli>(static_cast<double>(od_.GetSigned(kPidDerivativeTime, 0)) *
                                                   time_scale);
  const double cycle_ms = static_cast<double>(od_.GetSigned(kPidCycleTime, 0)) * time_scale;
  p.cycle = Ms{std::max<std::int64_t>(1, std::llround(cycle_ms))};
  p.response = blocks::EncoderPidProfile()
                   .DecodeResponse(static_cast<std::uint8_t>(od_.GetUnsigned(kPidResponse, 0)))
                   .value_or(blocks::PidResponse::kSingleOutput);
  return p;
}

void FunctionBlocks::UpdatePid(Ms elapsed, const blocks::ControlSources& sources) {
  const blocks::PidParams params = PidParameters();
  const Signal target =
      sources.Resolve(blocks::SourceRef{static_cast<std::uint8_t>(od_.GetUnsigned(kPidTargetSource, 0)),
                                        static_cast<std::uint8_t>(od_.GetUnsigned(kPidTargetNumber, 0))});
  const Signal feedback =
      sources.Resolve(blocks::SourceRef{static_cast<std::uint8_t>(od_.GetUnsigned(kPidFeedbackSource, 0)),
                                        static_cast<std::uint8_t>(od_.GetUnsigned(kPidFeedbackNumber, 0))});
  const bool enabled = target.available && feedback.available;
  if (!enabled) {
    pid_.Reset();
    pid_active_ = false;
    pid_inputs_pending_ = false;
  } else {
    if (!Same(target, seen_target_) || !Same(feedback, seen_feedback_)) pid_inputs_pending_ = true;
    // A loop that was asleep lets no cycle pass for the time it slept: its inputs were steady.
    const Ms e = pid_active_ ? elapsed : std::min(elapsed, Ms{1});
    const Ms before = pid_.NextStepAfter(params);
    pid_.Tick(e, params, target, feedback);
    if (e >= before) pid_inputs_pending_ = false;
    pid_active_ = pid_.Busy() || pid_inputs_pending_;
  }
  seen_target_ = target;
  seen_feedback_ = feedback;
  OdRef(od_, kPidOutput, 0).SetNumber(pid_.Output().value);
}

std::optional<FunctionBlocks::Ms> FunctionBlocks::NextChange() const {
  if (!pid_active_) return std::nullopt;
  return std::max(Ms{1}, pid_.NextStepAfter(PidParameters()));
}

void FunctionBlocks::Reset() {
  for (auto& l : lut_)
    l.Reset();
  pid_.Reset();
  pid_active_ = false;
  pid_inputs_pending_ = false;
  seen_target_ = seen_feedback_ = Signal::NotAvailable();
}

}  // namespace canfleet::devices::encoder
