#include "node/devices/quad_controller/ao_block.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "node/devices/quad_controller/ao_profile.hpp"

namespace canfleet::devices::quad {

namespace {

constexpr double kMax = kMaxOutputCurrent_mA;

double ClampCurrent(double mA) {
  return std::clamp(mA, 0.0, kMax);
}

}  // namespace

AoBlock::AoBlock(canopen::CanopenStack& stack, Scheduler& scheduler, QuadIo& io) : io_(io) {
  auto& od = stack.od();
  for (int n = 0; n < kPouts; ++n) {
    const std::uint8_t sub = SubOf(n);
    Refs& r = refs_[n];
    r.output_type = OdRef(od, kAoOutputType, sub);
    r.control = OdRef(od, kAoControlInput, sub);
    r.response = OdRef(od, kAoResponse, sub);
    r.min_current = OdRef(od, kAoMinimumCurrent, sub);
    r.breakpoint_current = OdRef(od, kAoBreakpointCurrent, sub);
    r.max_current = OdRef(od, kAoMaximumCurrent, sub);
    r.dither_frequency = OdRef(od, kAoDitherFrequency, sub);
    r.dither_amplitude = OdRef(od, kAoDitherAmplitude, sub);
    r.ramp_up = OdRef(od, kAoRampUp, sub);
    r.ramp_down = OdRef(od, kAoRampDown, sub);
    r.ramp_control = OdRef(od, kAoRampControl, sub);
    r.error_delay = OdRef(od, kAoErrorDelay, sub);
    r.measured = OdRef(od, kAoMeasuredCurrent, sub);
    r.process_value = OdRef(od, kAoProcessValue, sub);
    r.scaling1_pv = OdRef(od, kAoScaling1Pv, sub);
    r.scaling1_fv = OdRef(od, kAoScaling1Fv, sub);
    r.scaling2_pv = OdRef(od, kAoScaling2Pv, sub);
    r.scaling2_fv = OdRef(od, kAoScaling2Fv, sub);
    r.field_value = OdRef(od, kAoFieldValue, sub);
    r.fault_mode = OdRef(od, kAoFaultMode, sub);
    r.fault_fv = OdRef(od, kAoFaultFieldValue, sub);
    r.received_pv = OdRef(od, kReceivedPv, sub);
    r.pv_status = OdRef(od, kReceivedPvStatus, sub);
    outputs_[n].faults =
        std::make_unique<LoadFaults>(scheduler, stack, kDescProportionalOutput, sub, kBehaviourAnalogOutput);
  }
  // 2020h..2070h of every input that may control an output (§3.3.2-7).
  for (int ch = 0; ch < kInputs; ++ch) {
    for (std::size_t k = 0; k < input_points_[ch].size(); ++k)
      input_points_[ch][k] = OdRef(od, kAiProfileChain[k + 1], SubOf(ch));
  }
}

void AoBlock::Reset() {
  for (Output& o : outputs_) {
    o.present = 0;
    o.faults->Reset();
  }
}

// §3.5.24: a validated received PV is copied once, then the status is invalidated again.
void AoBlock::ApplyReceivedPv(int n) {
  Refs& r = refs_[n];
  if (r.pv_status.Get() != 1) return;
  const auto pv = r.received_pv.Get();
  r.process_value.Set(pv);
  r.pv_status.Set(0);
  const double pv1 = static_cast<double>(r.scaling1_pv.Get());
  const double pv2 = static_cast<double>(r.scaling2_pv.Get());
  double fv = static_cast<double>(pv);
  if (pv1 != pv2) {
    const double fv1 = static_cast<double>(r.scaling1_fv.Get());
    const double fv2 = static_cast<double>(r.scaling2_fv.Get());
    fv = fv1 + (fv - pv1) * (fv2 - fv1) / (pv2 - pv1);
  }
  r.field_value.Set(std::clamp<long long>(std::llround(fv), -32768, 32767));
}

double AoBlock::Target(int n, const AiBlock& ai) const {
  const Refs& r = refs_[n];
  const auto source = r.control.Get();
  if (source == kControlCan) return ClampCurrent(static_cast<double>(r.field_value.Get()));
  const int ch = static_cast<int>(source - 1);
  if (ch < 0 || ch >= kInputs || ai.Mode(ch) != OperatingMode::kNormal) return 0;
  const auto& p = input_points_[ch];
  const ProfileInputs in{static_cast<int>(p[0].Get()), static_cast<int>(p[1].Get()),
                         static_cast<int>(p[2].Get()), static_cast<int>(p[3].Get()),
                         static_cast<int>(p[4].Get()), static_cast<int>(p[5].Get())};
  const ProfileCurrents out{static_cast<int>(r.min_current.Get()),
                            static_cast<int>(r.breakpoint_current.Get()),
                            static_cast<int>(r.max_current.Get())};
  return ClampCurrent(
      ProfileCurrent(static_cast<std::uint8_t>(r.response.Get()), ai.FieldValue(ch), in, out));
}

double AoBlock::Highest(int n) const {
  const Refs& r = refs_[n];
  if (r.control.Get() == kControlCan) return kMax;
  return static_cast<double>(
      std::max({r.min_current.Get(), r.breakpoint_current.Get(), r.max_current.Get()}));
}

// §3.5.8-9: the ramp time is the time for 0 ↔ the highest current; a time of 0 is a step.
void AoBlock::Ramp(int n, double target) {
  Refs& r = refs_[n];
  Output& o = outputs_[n];
  const double highest = Highest(n);
  const bool up = target > o.present;
  const auto ramp_ms = up ? r.ramp_up.Get() : r.ramp_down.Get();
  if (ramp_ms <= 0 || highest <= 0) {
    o.present = target;
    return;
  }
  const double step = highest / static_cast<double>(ramp_ms);  // mA per 1 ms tick
  o.present = up ? std::min(target, o.present + step) : std::max(target, o.present - step);
}

void AoBlock::Publish(int n) {
  Refs& r = refs_[n];
  const Output& o = outputs_[n];
  const IoSignal& load = *io_.pout_load[n];
  const double current = load.Is(kLoadNominal) ? o.present : 0.0;
  const bool dithering = current > 0 && r.dither_amplitude.Get() > 0;
  io_.io.Publish(*io_.pout_on[n], o.present > 0 && !load.Is(kLoadShort));
  io_.io.Publish(*io_.pout_current[n], current);
  io_.io.Publish(*io_.pout_dither_amplitude[n],
                 dithering ? static_cast<double>(r.dither_amplitude.Get()) : 0.0);
  io_.io.Publish(*io_.pout_dither_frequency[n],
                 dithering ? static_cast<double>(r.dither_frequency.Get()) : 0.0);
  r.measured.Set(std::lround(current));
}

bool AoBlock::Update(const OutputConditions& conditions, const AiBlock& ai) {
  bool changed = false;
  for (int n = 0; n < kPouts; ++n) {
    Refs& r = refs_[n];
    Output& o = outputs_[n];
    const double before = o.present;
    ApplyReceivedPv(n);
    const bool current_mode = r.output_type.Get() == static_cast<std::int64_t>(OutputType::kCurrent);
    if (!current_mode) {
      o.present = 0;
      changed =
          o.faults->Update(false, *io_.pout_load[n], Duration::zero()) || changed || o.present != before;
      continue;
    }
    const bool can = r.control.Get() == kControlCan;
    const bool fault_applies = conditions.fault_state && r.fault_mode.Get() == 1;
    if (conditions.Stopped()) {
      o.present = 0;
    } else if (fault_applies) {
      if (conditions.fault_entered) r.field_value.Set(r.fault_fv.Get());
      o.present = ClampCurrent(static_cast<double>(r.fault_fv.Get()));
    } else if (can && !conditions.CanControlAllowed()) {
      o.present = 0;
    } else {
      const double target = Target(n, ai);
      const auto ramps = static_cast<RampControl>(r.ramp_control.Get());
      const bool use_ramps = ramps == RampControl::kAlways || (ramps == RampControl::kUnlessCan && !can);
      if (use_ramps)
        Ramp(n, target);
      else
        o.present = target;
    }
    Publish(n);
    changed = o.faults->Update(true, *io_.pout_load[n], std::chrono::milliseconds(r.error_delay.Get())) ||
              changed || o.present != before;
  }
  return changed;
}

}  // namespace canfleet::devices::quad
