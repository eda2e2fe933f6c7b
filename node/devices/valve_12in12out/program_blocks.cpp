#include "node/devices/valve_12in12out/program_blocks.hpp"

#include <algorithm>
#include <cmath>

namespace canfleet::devices::valve {

namespace {

using blocks::Signal;
using namespace std::chrono_literals;

constexpr std::chrono::milliseconds kStep{1};

bool Same(const Signal& a, const Signal& b) {
  return a.value == b.value && a.min == b.min && a.max == b.max && a.error == b.error &&
         a.available == b.available && a.has_range == b.has_range;
}

bool Same(const blocks::PidParams& a, const blocks::PidParams& b) {
  return a.gain == b.gain && a.ki == b.ki && a.kd == b.kd && a.ti == b.ti && a.td == b.td &&
         a.cycle == b.cycle && a.tolerance_percent == b.tolerance_percent && a.response == b.response;
}

std::uint8_t Digits(const OdRef& ref) {
  return static_cast<std::uint8_t>(std::clamp<std::int64_t>(ref.Get(), 0, 4));
}

blocks::SourceRef Ref(const OdRef& source, const OdRef& number) {
  return {static_cast<std::uint8_t>(source.Get()), static_cast<std::uint8_t>(number.Get())};
}

}  // namespace

ProgramBlocks::ProgramBlocks(canopen::ObjectDictionary& od, const ValveSources& sources) : sources_(sources) {
  for (int t = 0; t < kLookupTables; ++t) {
    Lut& l = luts_[t];
    const int yz = t + 1;
    l.source = OdRef(od, LutIndex(yz, 0), 0);
    l.number = OdRef(od, LutIndex(yz, 1), 0);
    l.repeat = OdRef(od, LutIndex(yz, 2), 0);
    l.y_digits = OdRef(od, LutIndex(yz, 4), 0);
    l.output = OdRef(od, LutIndex(yz, 8), 0);
    for (int k = 0; k < kLutPoints; ++k) {
      l.response[k] = OdRef(od, LutIndex(yz, 5), SubOf(k));
      l.x[k] = OdRef(od, LutIndex(yz, 6), SubOf(k));
      l.y[k] = OdRef(od, LutIndex(yz, 7), SubOf(k));
    }
  }
  for (int n = 0; n < kPids; ++n) {
    Pid& p = pids_[n];
    const std::uint8_t sub = SubOf(n);
    p.tolerance = OdRef(od, kPidTolerance, sub);
    p.ki = OdRef(od, kPidKi, sub);
    p.kd = OdRef(od, kPidKd, sub);
    p.target_source = OdRef(od, kPidTargetSource, sub);
    p.target_number = OdRef(od, kPidTargetNumber, sub);
    p.feedback_source = OdRef(od, kPidFeedbackSource, sub);
    p.feedback_number = OdRef(od, kPidFeedbackNumber, sub);
    p.response = OdRef(od, kPidResponse, sub);
    p.digits = OdRef(od, kPidTimingDigits, sub);
    p.gain = OdRef(od, kPidGain, sub);
    p.ti = OdRef(od, kPidTi, sub);
    p.td = OdRef(od, kPidTd, sub);
    p.cycle = OdRef(od, kPidCycle, sub);
    p.output = OdRef(od, kPidOutput, sub);
  }
  for (int y = 0; y < kMathBlocks; ++y) {
    Math& m = maths_[y];
    m.block = blocks::MathBlock(blocks::ValveMathProfile(), static_cast<std::uint8_t>(y + 1));
    const std::uint8_t sub = SubOf(y);
    m.enable = OdRef(od, kMathEnable, sub);
    m.out_scaling1 = OdRef(od, kMathOutScaling1, sub);
    m.out_scaling2 = OdRef(od, kMathOutScaling2, sub);
    m.out_digits = OdRef(od, kMathOutDigits, sub);
    m.output = OdRef(od, kMathOutput, sub);
    for (int i = 0; i < 6; ++i) {
      const std::uint8_t in = SubOf(i);
      m.source[i] = OdRef(od, MathIndex(y + 1, kMathInSource), in);
      m.number[i] = OdRef(od, MathIndex(y + 1, kMathInNumber), in);
      m.function[i] = OdRef(od, MathIndex(y + 1, kMathInFunction), in);
      m.digits[i] = OdRef(od, MathIndex(y + 1, kMathInDigits), in);
      m.scaling1[i] = OdRef(od, MathIndex(y + 1, kMathInScaling1), in);
      m.scaling2[i] = OdRef(od, MathIndex(y + 1, kMathInScaling2), in);
      m.gain[i] = OdRef(od, MathIndex(y + 1, kMathInGain), in);
    }
    for (int f = 0; f < 3; ++f)
      m.op[f] = OdRef(od, MathIndex(y + 1, kMathOperator), SubOf(f));
  }
  for (int b = 0; b < kLogicBlocks; ++b) {
    Logic& l = logics_[b];
    const std::uint8_t sub = SubOf(b);
    l.enable = OdRef(od, kLogicEnable, sub);
    l.selected = OdRef(od, kLogicSelectedTable, sub);
    l.output = OdRef(od, kLogicOutput, sub);
    for (int f = 0; f < 3; ++f) {
      l.table[f] = OdRef(od, LogicIndex(b + 1, 0x01), SubOf(f));
      l.op[f] = OdRef(od, LogicIndex(b + 1, 0x02), SubOf(f));
      for (int c = 0; c < 3; ++c) {
        for (int k = 0; k < 5; ++k)
          l.conditions[f][c][k] = OdRef(od, LogicConditionIndex(b + 1, f + 1, c + 1), SubOf(k));
      }
    }
  }
}

void ProgramBlocks::Reset() {
  for (Lut& l : luts_)
    l.table.Reset();
  for (Pid& p : pids_) {
    p.pid.Reset();
    p.has_last = false;
  }
}

// §1.9: inputs normalised by their own scaling, gains, three functions, result to 4021h..4023h.
void ProgramBlocks::RunMath(Math& m) {
  blocks::MathBlockParams& params = m.params;
  params.enabled = m.enable.Get() != 0;
  params.inputs.resize(6);
  params.operators.resize(3);
  if (params.enabled) {
    for (int i = 0; i < 6; ++i) {
      blocks::MathInputParams& in = params.inputs[i];
      in.source = Ref(m.source[i], m.number[i]);
      in.function = static_cast<std::uint8_t>(m.function[i].Get());
      in.decimal_digits = Digits(m.digits[i]);
      in.scaling1 = static_cast<double>(m.scaling1[i].Get());
      in.scaling2 = static_cast<double>(m.scaling2[i].Get());
      in.gain = static_cast<double>(m.gain[i].Get()) / 100.0;
    }
    for (int f = 0; f < 3; ++f)
      params.operators[f] = static_cast<std::uint8_t>(m.op[f].Get());
  }
  params.output_scaling1 = static_cast<double>(m.out_scaling1.Get());
  params.output_scaling2 = static_cast<double>(m.out_scaling2.Get());
  params.output_digits = Digits(m.out_digits);
  m.output.SetNumber(m.block.Update(params, sources_.sources()).value);
}

// §1.7: data or time response over 11 points; output 3yz8h.
void ProgramBlocks::RunLut(Lut& l, std::chrono::milliseconds elapsed) {
  const blocks::SourceRef source = Ref(l.source, l.number);
  blocks::LookupTableParams& params = l.params;
  params.points.resize(kLutPoints);
  // "A selection of Control Source Not Used disables the associated lookup table" (§3.4.62): its
  // points are not read then.
  if (source.source != 0) {
    params.x_axis_type = l.response[0].Get() == 1 ? blocks::XAxisType::kTime : blocks::XAxisType::kData;
    params.auto_repeat = l.repeat.Get() != 0;
    params.y_digits = Digits(l.y_digits);
    const auto& profile = l.table.profile();
    for (int k = 0; k < kLutPoints; ++k) {
      blocks::LutPoint& p = params.points[k];
      p.x = static_cast<double>(l.x[k].Get());
      p.y = static_cast<double>(l.y[k].Get());
      // Sub 1 is the X-axis type, so point 1's response is never looked at (§1.7.3).
      p.response = k == 0 ? blocks::PointResponse::kRampTo
                          : profile.DecodeResponse(static_cast<std::uint8_t>(l.response[k].Get()))
                                .value_or(blocks::PointResponse::kRampTo);
    }
  }
  const Signal x = sources_.Resolve(source);
  l.output.SetNumber(l.table.Update(params, x, elapsed).value);
}

// §1.8: conditions, table selection A -> B -> C, 3310h and 3320h.
void ProgramBlocks::RunLogic(Logic& l) {
  blocks::LogicBlockParams params;
  params.enabled = l.enable.Get() != 0;
  for (int f = 0; f < 3 && params.enabled; ++f) {
    blocks::LogicFunction& fn = params.functions[f];
    fn.table = static_cast<std::uint8_t>(l.table[f].Get());
    fn.op = blocks::DecodeFunctionOperator(static_cast<std::uint8_t>(l.op[f].Get()))
                .value_or(blocks::FunctionOperator::kDefaultTable);
    for (int c = 0; c < 3; ++c) {
      const auto& sub = l.conditions[f][c];
      fn.conditions[c].arg1 = Ref(sub[0], sub[1]);
      fn.conditions[c].arg2 = Ref(sub[2], sub[3]);
      fn.conditions[c].op = blocks::DecodeCompareOp(static_cast<std::uint8_t>(sub[4].Get()))
                                .value_or(blocks::CompareOp::kEqual);
    }
  }
  const blocks::LogicResult& r = l.block.Update(params, sources_.sources());
  l.selected.Set(r.table);
  l.output.SetNumber(r.output.value);
}

blocks::PidParams ProgramBlocks::ReadPidParams(const Pid& p) const {
  blocks::PidParams params;
  // 6459h decimals of seconds: value x 10^(3 - digits) milliseconds.
  const double to_ms = std::pow(10.0, 3.0 - static_cast<double>(Digits(p.digits)));
  params.gain = static_cast<double>(p.gain.Get()) / 10.0;
  params.ki = static_cast<double>(p.ki.Get()) / 10.0;
  params.kd = static_cast<double>(p.kd.Get()) / 10.0;
  params.ti = std::chrono::duration<double, std::milli>(static_cast<double>(p.ti.Get()) * to_ms);
  params.td = std::chrono::duration<double, std::milli>(static_cast<double>(p.td.Get()) * to_ms);
  params.cycle = std::chrono::milliseconds(
      std::max<std::int64_t>(1, std::llround(static_cast<double>(p.cycle.Get()) * to_ms)));
  params.tolerance_percent = static_cast<double>(p.tolerance.Get()) / 10.0;
  params.response = blocks::ValvePidProfile()
                        .DecodeResponse(static_cast<std::uint8_t>(p.response.Get()))
                        .value_or(blocks::PidResponse::kSingleOutput);
  return params;
}

// §1.6 Figure 14, every 7456h while both inputs are set.
void ProgramBlocks::RunPid(Pid& p, std::chrono::milliseconds elapsed) {
  const Signal target = sources_.Resolve(Ref(p.target_source, p.target_number));
  const Signal feedback = sources_.Resolve(Ref(p.feedback_source, p.feedback_number));
  if (!target.available || !feedback.available) {
    // "Unless both the target and feedback inputs have legitimate control sources selected, the PID
    // loop is disabled": no cycles to count.
    p.pid.Reset();
    p.has_last = false;
    p.dirty = false;
    p.output.SetNumber(p.pid.Output().value);
    return;
  }
  const blocks::PidParams params = ReadPidParams(p);
  // The time before this run carried the previous inputs; a loop at rest (E = 0) would only
  // repeat itself there, so it is not replayed.
  const bool was_faulted = p.target.error || p.feedback.error;  // a faulted loop holds: nothing to replay
  if (p.has_last && !was_faulted && (p.pid.Busy() || p.dirty) && elapsed > kStep)
    p.pid.Tick(elapsed - kStep, p.params, p.target, p.feedback);
  if (!p.has_last || !Same(params, p.params) || !Same(target, p.target) || !Same(feedback, p.feedback))
    p.dirty = true;
  const bool steps = kStep >= p.pid.NextStepAfter(params);
  p.pid.Tick(kStep, params, target, feedback);
  if (steps) p.dirty = false;
  p.params = params;
  p.target = target;
  p.feedback = feedback;
  p.has_last = true;
  p.output.SetNumber(p.pid.Output().value);
}

bool ProgramBlocks::Run(std::chrono::milliseconds elapsed) {
  bool changed = false;
  for (Math& m : maths_) {
    const Signal before = m.block.Output();
    RunMath(m);
    changed |= !Same(before, m.block.Output());
  }
  for (Lut& l : luts_) {
    const Signal before = l.table.Output();
    RunLut(l, elapsed);
    changed |= !Same(before, l.table.Output());
  }
  for (Logic& l : logics_) {
    const Signal before = l.block.Output();
    RunLogic(l);
    changed |= !Same(before, l.block.Output());
  }
  for (Pid& p : pids_) {
    const Signal before = p.pid.Output();
    RunPid(p, elapsed);
    changed |= !Same(before, p.pid.Output());
  }
  return changed;
}

std::optional<std::chrono::milliseconds> ProgramBlocks::NextWake() const {
  std::optional<std::chrono::milliseconds> wake;
  const auto earliest = [&wake](std::chrono::milliseconds t) {
    t = std::max(t, kStep);
    wake = wake ? std::min(*wake, t) : t;
  };
  for (const Lut& l : luts_) {
    if (auto next = l.table.NextChangeAfter()) earliest(*next);
  }
  for (const Pid& p : pids_) {
    // A loop runs every cycle until a cycle has seen its inputs and E has been 0 twice.
    // A faulted input holds the output (blocks/pid.hpp) until the fault clears, which changes the input.
    const bool faulted = p.target.error || p.feedback.error;
    if (p.has_last && (p.dirty || (!faulted && (p.pid.Busy() || !p.pid.Enabled()))))
      earliest(p.pid.NextStepAfter(p.params));
  }
  return wake;
}

}  // namespace canfleet::devices::valve
