#include "node/devices/quad_controller/ai_block.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace canfleet::devices::quad {

namespace {

using canopen::Origin;
using canopen::SdoAbort;
using canopen::SubObject;
using namespace std::chrono_literals;

/// 6125h write value "zero" (bytes 7Ah 65h 72h 6Fh), §3.3.20.
constexpr std::uint32_t kZeroSignature = 0x6F72657A;

/// Full scale of a field value, by sensor type (§3.3.12).
int FullScale(SensorType type) {
  switch (type) {
    case SensorType::kVoltage5V:
      return 5000;
    case SensorType::kVoltage10V:
    case SensorType::kFrequency:
    case SensorType::kPwm:
      return 10000;
    case SensorType::kCurrent4To20:
    case SensorType::kCurrent0To20:
      return 20000;
  }
  return 10000;
}

int ClampToScale(double value, SensorType type) {
  return static_cast<int>(std::clamp(std::lround(value), 0L, static_cast<long>(FullScale(type))));
}

bool Measures(OperatingMode mode) {
  return mode == OperatingMode::kNormal || mode == OperatingMode::kOnOff;
}

}  // namespace

AiBlock::AiBlock(canopen::CanopenStack& stack, Scheduler& scheduler, const QuadIo& io) : io_(io) {
  auto& od = stack.od();
  error_check_enable_ = OdRef(od, kAiErrorCheckEnable, 1);
  for (int ch = 0; ch < kInputs; ++ch) {
    const std::uint8_t sub = SubOf(ch);
    Refs& r = refs_[ch];
    r.type = OdRef(od, kAiSensorType, sub);
    r.mode = OdRef(od, kAiOperatingMode, sub);
    r.fv = OdRef(od, kAiFieldValue, sub);
    r.pv = OdRef(od, kAiProcessValue, sub);
    r.low_threshold = OdRef(od, kDiLowThreshold, sub);
    r.high_threshold = OdRef(od, kDiHighThreshold, sub);
    r.error_min = OdRef(od, kAiErrorMinimum, sub);
    r.error_max = OdRef(od, kAiErrorMaximum, sub);
    r.error_delay = OdRef(od, kAiErrorDelay, sub);
    r.filter_type = OdRef(od, kAiFilterType, sub);
    r.filter_constant = OdRef(od, kAiFilterConstant, sub);
    r.fv1 = OdRef(od, kAiScaling1Fv, sub);
    r.pv1 = OdRef(od, kAiScaling1Pv, sub);
    r.fv2 = OdRef(od, kAiScaling2Fv, sub);
    r.pv2 = OdRef(od, kAiScaling2Pv, sub);
    r.offset = OdRef(od, kAiOffset, sub);
    if (ch >= kAnalogInputs)
      r.window = OdRef(od, kAiFrequencyWindow, static_cast<std::uint8_t>(ch - kAnalogInputs + 1));

    Channel& c = channels_[ch];
    c.low = std::make_unique<DelayedFault>(
        scheduler, stack, MakeErrorEntry(kEmcyInputLow, kDescAnalogInput, sub), kBehaviourAnalogInput);
    c.high = std::make_unique<DelayedFault>(
        scheduler, stack, MakeErrorEntry(kEmcyInputHigh, kDescAnalogInput, sub), kBehaviourAnalogInput);

    SubObject& autozero = OdRef(od, kAiAutozero, sub).sub();
    autozero.AddValidator([](const SubObject&, std::span<const std::uint8_t> data, Origin) {
      return canopen::DecodeUnsignedLe(data) == kZeroSignature ? SdoAbort::kNone : SdoAbort::kInvalidValue;
    });
    // Only a network write is a command; stored or restored values are not (and 6125h is not stored).
    autozero.AddListener([this, ch](SubObject&, Origin origin) {
      if (origin != Origin::kDevice) Autozero(ch);
    });
  }
  if (auto* store = stack.store()) store->Exclude(kAiAutozero);
}

void AiBlock::ResetChannel(Channel& c) {
  c.filtered = 0;
  c.filter_started = false;
  c.sum = 0;
  c.count = 0;
  c.window_start_upulses = c.phase_upulses;
  c.window_elapsed_ms = 0;
  c.frequency_fv = 0;
}

void AiBlock::Reset() {
  for (Channel& c : channels_) {
    ResetChannel(c);
    c.fv = 0;
    c.on = false;
    c.last_type = 0;
    c.last_mode = 0xFF;
    c.low->Reset();
    c.high->Reset();
  }
}

// §3.3.9: the number of pulses is sampled at the end of the measuring window, then the frequency
// is calculated. Windows are whole milliseconds, so a 1 ms count is exact.
bool AiBlock::CountPulses() {
  bool changed = false;
  for (int ch = kAnalogInputs; ch < kInputs; ++ch) {
    Channel& c = channels_[ch];
    if (Type(ch) != SensorType::kFrequency || !Measures(Mode(ch))) {
      changed = changed || c.window_start_upulses != c.phase_upulses || c.window_elapsed_ms != 0 ||
                c.frequency_fv != 0;
      c.window_start_upulses = c.phase_upulses;
      c.window_elapsed_ms = 0;
      c.frequency_fv = 0;
      continue;
    }
    changed = true;  // the window's millisecond count moves on
    const double hz = io_.fin_frequency[ch - kAnalogInputs]->Number();
    c.phase_upulses += static_cast<std::uint64_t>(std::llround(hz * 1000.0));  // µpulses per ms
    ++c.window_elapsed_ms;
    const int window = static_cast<int>(std::clamp<std::int64_t>(refs_[ch].window.Get(), 10, 10000));
    if (c.window_elapsed_ms < window) continue;
    const std::uint64_t pulses = c.phase_upulses / 1000000 - c.window_start_upulses / 1000000;
    c.frequency_fv =
        static_cast<int>(std::min<std::uint64_t>(pulses * 1000 / static_cast<std::uint64_t>(window), 10000));
    c.window_start_upulses = c.phase_upulses;
    c.window_elapsed_ms = 0;
  }
  return changed;
}

bool AiBlock::Counting() const {
  for (int ch = kAnalogInputs; ch < kInputs; ++ch) {
    if (Type(ch) == SensorType::kFrequency && Measures(Mode(ch))) return true;
  }
  return false;
}

int AiBlock::Measure(int ch) const {
  if (!Measures(Mode(ch))) return 0;
  const SensorType type = Type(ch);
  switch (type) {
    case SensorType::kVoltage5V:
    case SensorType::kVoltage10V:
      return ch < kAnalogInputs ? ClampToScale(io_.ain_voltage[ch]->Number(), type) : 0;
    case SensorType::kCurrent4To20:
    case SensorType::kCurrent0To20:
      return ch < kAnalogInputs ? ClampToScale(io_.ain_current[ch]->Number() * 1000.0, type)
                                : 0;  // 7100h: uA
    case SensorType::kPwm:
      return ch >= kAnalogInputs ? ClampToScale(io_.fin_duty[ch - kAnalogInputs]->Number() * 100.0, type) : 0;
    case SensorType::kFrequency:
      return ch >= kAnalogInputs ? channels_[ch].frequency_fv : 0;
  }
  return 0;
}

// §3.3.23: 0 none; 1 moving average V_N = V_{N-1} + (Input - V_{N-1}) / C; 2 repeating average,
// the mean of every N samples (the output holds in between). C = N = 61A1h; 0 counts as 1. Other
// filter types are treated as none. The moving average starts from the first sample.
bool AiBlock::Filter(int ch, int fv, double& out) {
  Channel& c = channels_[ch];
  const auto type = Type(ch) == SensorType::kFrequency ? 0 : refs_[ch].filter_type.Get();
  const double constant = static_cast<double>(std::max<std::int64_t>(refs_[ch].filter_constant.Get(), 1));
  switch (type) {
    case 1:
      c.filtered = c.filter_started ? c.filtered + (fv - c.filtered) / constant : fv;
      c.filter_started = true;
      break;
    case 2:
      c.sum += fv;
      if (++c.count < static_cast<int>(constant)) return false;
      c.filtered = c.sum / constant;
      c.sum = 0;
      c.count = 0;
      break;
    default:
      c.filtered = fv;
      break;
  }
  out = c.filtered;
  return true;
}

// DS-404 linear scaling through calibration points 1 and 2 (§2.3), offset 7124h added after.
double AiBlock::Scale(int ch, double fv) const {
  const Refs& r = refs_[ch];
  const double fv1 = static_cast<double>(r.fv1.Get());
  const double fv2 = static_cast<double>(r.fv2.Get());
  double pv = fv;
  if (fv1 != fv2) {
    const double pv1 = static_cast<double>(r.pv1.Get());
    const double pv2 = static_cast<double>(r.pv2.Get());
    pv = pv1 + (fv - fv1) * (pv2 - pv1) / (fv2 - fv1);
  }
  return pv + static_cast<double>(r.offset.Get());
}

void AiBlock::WriteProcessValue(int ch, double pv) {
  refs_[ch].pv.Set(std::clamp<long long>(std::llround(pv), -32768, 32767));
}

bool AiBlock::Sample() {
  const auto enabled = error_check_enable_.Get();
  bool changed = false;
  for (int ch = 0; ch < kInputs; ++ch) {
    Refs& r = refs_[ch];
    Channel& c = channels_[ch];
    const auto before = c.State();
    const auto type = static_cast<std::uint16_t>(r.type.Get());
    const auto mode = static_cast<std::uint8_t>(r.mode.Get());
    if (type != c.last_type || mode != c.last_mode) {
      ResetChannel(c);
      c.last_type = type;
      c.last_mode = mode;
    }
    c.fv = Measure(ch);
    r.fv.Set(c.fv);

    // §2.2: <= low threshold → OFF; >= high threshold → ON; in between the state holds.
    if (c.fv <= r.low_threshold.Get())
      c.on = false;
    else if (c.fv >= r.high_threshold.Get())
      c.on = true;

    if (Measures(Mode(ch))) {
      double filtered = 0;
      if (Filter(ch, c.fv, filtered)) WriteProcessValue(ch, Scale(ch, filtered));
    } else {
      r.pv.Set(0);
    }

    const bool check = ((enabled >> ch) & 1) != 0 && Measures(Mode(ch));
    const Duration delay = std::chrono::milliseconds(r.error_delay.Get());
    c.low->Update(check && c.fv < r.error_min.Get(), delay);
    c.high->Update(check && c.fv > r.error_max.Get(), delay);
    changed = changed || c.State() != before;
  }
  return changed;
}

void AiBlock::Autozero(int ch) {
  Refs& r = refs_[ch];
  Channel& c = channels_[ch];
  const double unshifted = Scale(ch, c.filtered) - static_cast<double>(r.offset.Get());
  r.offset.Set(std::clamp<long long>(std::llround(-unshifted), -32768, 32767));
  if (Measures(Mode(ch))) WriteProcessValue(ch, Scale(ch, c.filtered));
}

}  // namespace canfleet::devices::quad
