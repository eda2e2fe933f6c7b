#include "node/devices/encoder_dual_valve/pulse_inputs.hpp"

#include <algorithm>
#include <cmath>

#include "node/devices/blocks/analog_input.hpp"
#include "node/devices/family/family_error_policy.hpp"

namespace canfleet::devices::encoder {
namespace {

using Ms = PulseInputs::Ms;
constexpr Ms kFilterCall{1};  // "inputs are sampled multiple times per millisecond" (4.2)

double SaturateInt16(double v) {
  return std::clamp(std::round(v), -32768.0, 32767.0);
}

// Table 3: the lowest frequency each range measures (below it no edge falls in the window).
constexpr std::array<double, 3> kLowestFrequency{0.5, 10.0, 100.0};

}  // namespace

PulseInputs::PulseInputs(canopen::CanopenStack& stack, Scheduler& scheduler, EncoderIo& io)
    : stack_(stack), io_(io) {
  auto& od = stack.od();
  for (int ch = 0; ch < kInputs; ++ch) {
    const std::uint8_t sub = SubOf(ch);
    Refs& r = refs_[ch];
    r.sensor_type = OdRef(od, kAiSensorType, sub);
    r.mode = OdRef(od, kAiOperatingMode, sub);
    r.range = OdRef(od, kAiRange, sub);
    r.fv_digits = OdRef(od, kAiFvDigits, sub);
    r.pull = OdRef(od, kDiPull, sub);
    r.filter_type = OdRef(od, kAiFilterType, sub);
    r.filter_constant = OdRef(od, kAiFilterConstant, sub);
    r.error_enable = OdRef(od, kAiErrorEnable, sub);
    r.hysteresis = OdRef(od, kAiErrorHysteresis, sub);
    r.delay = OdRef(od, kAiErrorDelay, sub);
    r.span_start = OdRef(od, kAiSpanStart, sub);
    r.span_end = OdRef(od, kAiSpanEnd, sub);
    r.scaling1_fv = OdRef(od, kAiScaling1Fv, sub);
    r.scaling1_pv = OdRef(od, kAiScaling1Pv, sub);
    r.scaling2_fv = OdRef(od, kAiScaling2Fv, sub);
    r.scaling2_pv = OdRef(od, kAiScaling2Pv, sub);
    r.field_value = OdRef(od, kAiFieldValue, sub);
    r.process_value = OdRef(od, kAiProcessValue, sub);
    Channel& c = channels_[ch];
    c.high = std::make_unique<DelayedFault>(
        scheduler, stack, family::MakeFamilyEntry(kEmcyInput, kDescHigh, sub), kBehaviourAnalogInput);
    c.low = std::make_unique<DelayedFault>(
        scheduler, stack, family::MakeFamilyEntry(kEmcyInput, kDescLow, sub), kBehaviourAnalogInput);
  }
  read_state_ = OdRef(od, kDiReadState, 1);
  polarity_ = OdRef(od, kDiPolarity, 1);
  qd_scaler_ = OdRef(od, kQdScaler, 0);
  qd_direction_ = OdRef(od, kQdDirection, 0);
  qd_offset_ = OdRef(od, kQdOffset, 0);
  qd_pulses_ = OdRef(od, kQdPulsesPerRev, 0);
}

InputMode PulseInputs::Mode(int ch) const {
  const Refs& r = refs_[ch];
  const auto mode = r.mode.Get();
  const auto type = r.sensor_type.Get();
  if (mode == static_cast<std::int64_t>(OperatingMode::kOff)) return InputMode::kOff;
  if (type == static_cast<std::int64_t>(SensorType::kQuadrature)) return InputMode::kQuadrature;
  if (mode == static_cast<std::int64_t>(OperatingMode::kDigital)) return InputMode::kDigital;
  if (type == static_cast<std::int64_t>(SensorType::kFrequency)) return InputMode::kFrequency;
  if (type == static_cast<std::int64_t>(SensorType::kPwm)) return InputMode::kPwm;
  return InputMode::kOff;
}

std::string PulseInputs::IgnoredInput(const IoSignal& input) const {
  const bool by_channels = io_.drive->Is(kDriveChannels);
  for (int ch = 0; ch < kInputs; ++ch) {
    const InputMode mode = Mode(ch);
    bool read = false;
    if (&input == io_.level[ch])
      read = mode == InputMode::kDigital;
    else if (&input == io_.frequency[ch])
      read = mode == InputMode::kFrequency || mode == InputMode::kPwm || (by_channels && PairIsQuadrature());
    else if (&input == io_.duty[ch])
      read = mode == InputMode::kPwm;
    else
      continue;
    if (read) return {};
    const std::string sub = std::to_string(ch + 1);
    const char* reads = "it reads none of the pin's signals";
    switch (mode) {
      case InputMode::kDigital:
        reads = "it reads the pin's level";
        break;
      case InputMode::kFrequency:
        reads = "it reads the pin's frequency";
        break;
      case InputMode::kPwm:
        reads = "it reads the pin's duty cycle and frequency";
        break;
      case InputMode::kQuadrature:
        reads =
            "a quadrature pair turns with ENC.drive: ENC.speed_rpm, ENC.speed_counts_s, or INn.frequency_Hz "
            "when ENC.drive = channels";
        break;
      case InputMode::kOff:
        break;
    }
    return IgnoredNotice(input,
                         "IN" + sub + "'s configuration (6112h sub " + sub + " = " +
                             std::to_string(refs_[ch].mode.Get()) + ", 6110h sub " + sub + " = " +
                             std::to_string(refs_[ch].sensor_type.Get()) + ")",
                         reads);
  }
  const bool rpm = io_.drive->Is(kDriveRpm);
  if ((&input == io_.speed_rpm || &input == io_.pulses_per_rev) && !rpm)
    return IgnoredNotice(input, "ENC.drive = " + std::string(io_.drive->Enum()), "ENC.drive = rpm reads it");
  if (&input == io_.speed_counts && !io_.drive->Is(kDriveCounts))
    return IgnoredNotice(input, "ENC.drive = " + std::string(io_.drive->Enum()),
                         "ENC.drive = counts reads it");
  return {};
}

QuadratureParams PulseInputs::Quadrature() const {
  QuadratureParams q;
  q.scaler = qd_scaler_.GetNumber();
  q.inverted = qd_direction_.Get() == 1;
  q.offset = qd_offset_.Get();
  q.pulses_per_rev = qd_pulses_.Get();
  return q;
}

// 1.2.1: "Both inputs need to be configured as one of the Quadrature Encoder input types".
bool PulseInputs::PairIsQuadrature() const {
  return Mode(0) == InputMode::kQuadrature && Mode(1) == InputMode::kQuadrature;
}

bool PulseInputs::PinHigh(int ch) const {
  const IoSignal& level = *io_.level[ch];
  if (level.Is(kLevelHigh)) return true;
  if (level.Is(kLevelLow)) return false;
  // 1.2.2: floating, the 1 kOhm pull-up reads ON; with the pull-down or no resistor, OFF.
  return refs_[ch].pull.Get() == static_cast<std::int64_t>(PullMode::kPullUp);
}

void PulseInputs::UpdateDigital(int ch) {
  Channel& c = channels_[ch];
  const bool pin = PinHigh(ch);
  if (Mode(ch) != InputMode::kDigital) {
    c.digital = false;
    c.pin_before = pin;
    c.response = -1;
    return;
  }
  const std::int64_t response = refs_[ch].range.Get();
  if (response != c.response) {
    c.response = response;
    if (response == static_cast<std::int64_t>(DigitalRange::kLatched)) c.digital = false;  // starts OFF
  }
  switch (static_cast<DigitalRange>(response)) {
    case DigitalRange::kInverse:
      c.digital = !pin;
      break;
    case DigitalRange::kLatched:
      if (pin && !c.pin_before) c.digital = !c.digital;  // "push-button": OFF->ON toggles
      break;
    case DigitalRange::kNormal:
    default:
      c.digital = pin;
      break;
  }
  c.pin_before = pin;
}

double PulseInputs::Measured(int ch, TimePoint now) const {
  const Refs& r = refs_[ch];
  const auto range = static_cast<std::size_t>(std::clamp<std::int64_t>(r.range.Get(), 0, 2));
  const double scale = blocks::PowerOfTen(static_cast<std::uint8_t>(r.fv_digits.Get()));
  switch (Mode(ch)) {
    case InputMode::kOff:
      return 0.0;
    case InputMode::kQuadrature: {
      if (!PairIsQuadrature()) return 0.0;
      const QuadratureParams q = Quadrature();
      switch (static_cast<QuadratureRange>(range)) {
        case QuadratureRange::kCount:
          return SaturateInt16(ScaledCount(counter_.Steps(shaft_.EdgesAt(now)), q));
        case QuadratureRange::kDirection:
          return last_forward_ && (*last_forward_ != q.inverted) ? 1.0 : 0.0;
        case QuadratureRange::kSpeed:
          return SaturateInt16(SpeedRpm(shaft_.Velocity(), q) * scale);
      }
      return 0.0;
    }
    case InputMode::kFrequency: {
      const double f = io_.frequency[ch]->Number();
      return f < kLowestFrequency[range] ? 0.0 : SaturateInt16(f * scale);
    }
    case InputMode::kPwm: {
      const double f = io_.frequency[ch]->Number();
      const bool in_band = range == 0 ? (f > 0.0 && f < 1000.0) : f > 100.0;
      return in_band ? SaturateInt16(io_.duty[ch]->Number() * scale) : 0.0;
    }
    case InputMode::kDigital:
      return channels_[ch].digital ? 1.0 : 0.0;
  }
  return 0.0;
}

bool PulseInputs::Moving(int ch) const {
  return Mode(ch) == InputMode::kQuadrature && PairIsQuadrature() &&
         refs_[ch].range.Get() == static_cast<std::int64_t>(QuadratureRange::kCount) &&
         shaft_.Velocity() != 0.0;
}

blocks::FilterParams PulseInputs::Filter(int ch) const {
  blocks::FilterParams f;
  f.type = blocks::DecodeFilterType(static_cast<std::uint8_t>(refs_[ch].filter_type.Get()), false)
               .value_or(blocks::FilterType::kNone);
  f.constant = static_cast<std::uint16_t>(std::clamp<std::int64_t>(refs_[ch].filter_constant.Get(), 1, 1000));
  return f;
}

// Digital inputs and channels that are off are not checked (the family's rule, Quad §3.3.10).
blocks::SpanParams PulseInputs::Span(int ch) const {
  const Refs& r = refs_[ch];
  blocks::SpanParams s;
  const InputMode mode = Mode(ch);
  s.enabled = r.error_enable.Get() != 0 && mode != InputMode::kOff && mode != InputMode::kDigital;
  s.span_start = static_cast<double>(r.span_start.Get());
  s.span_end = static_cast<double>(r.span_end.Get());
  s.hysteresis = static_cast<double>(r.hysteresis.Get());
  s.delay = Ms{r.delay.Get()};
  return s;
}

void PulseInputs::Publish(int ch) {
  Refs& r = refs_[ch];
  const Channel& c = channels_[ch];
  blocks::AnalogInputParams line;
  line.scaling1_fv = static_cast<double>(r.scaling1_fv.Get());
  line.scaling1_pv = static_cast<double>(r.scaling1_pv.Get());
  line.scaling2_fv = static_cast<double>(r.scaling2_fv.Get());
  line.scaling2_pv = static_cast<double>(r.scaling2_pv.Get());
  r.field_value.SetNumber(c.fv);
  r.process_value.SetNumber(std::round(blocks::ScaleToProcessValue(line, c.fv)));
}

void PulseInputs::Update(TimePoint now, Ms elapsed) {
  std::int64_t bits = 0;
  for (int ch = 0; ch < kInputs; ++ch) {
    Channel& c = channels_[ch];
    UpdateDigital(ch);
    const double measured = Measured(ch, now);
    const blocks::FilterParams filter = Filter(ch);
    const blocks::SpanParams span = Span(ch);
    // An input that was idle lets no time pass for its filter: the new value arrived now.
    const Ms e = c.was_busy ? elapsed : std::min(elapsed, kFilterCall);
    if (filter.type == blocks::FilterType::kNone) {
      c.filter.Reset(measured);
      c.fv = measured;
      c.span.Update(span, c.fv, e);
    } else {
      Ms remaining = e;
      while (remaining >= kFilterCall) {
        if (c.filter.Settled(filter, measured)) {
          c.span.Update(span, c.fv, remaining);
          remaining = Ms{0};
          break;
        }
        c.filter.Step(filter, measured);
        c.fv = std::round(c.filter.Value());
        c.span.Update(span, c.fv, kFilterCall);
        remaining -= kFilterCall;
      }
      if (e < kFilterCall) c.span.Update(span, c.fv, Ms{0});
    }
    c.settled = filter.type == blocks::FilterType::kNone || c.filter.Settled(filter, measured);
    c.was_busy = !c.settled || c.span.Busy() || Moving(ch);
    Publish(ch);
    c.high->Update(c.span.Fault() == blocks::SpanFlag::kHigh, Duration::zero());
    c.low->Update(c.span.Fault() == blocks::SpanFlag::kLow, Duration::zero());
    if (Mode(ch) == InputMode::kDigital && (c.digital != polarity_.Bit(static_cast<unsigned>(ch))))
      bits |= std::int64_t{1} << ch;
  }
  if (read_state_.Set(bits)) stack_.pdo().NotifyChanged(read_state_.sub());
}

void PulseInputs::SampleOnRead(int ch, TimePoint now) {
  if (!Moving(ch) || Filter(ch).type != blocks::FilterType::kNone) return;
  channels_[ch].fv = Measured(ch, now);
  Publish(ch);
}

blocks::Signal PulseInputs::AsSource(int ch) const {
  const Refs& r = refs_[ch];
  const Channel& c = channels_[ch];
  const InputMode mode = Mode(ch);
  blocks::Signal s;
  s.value = c.fv;
  s.min = static_cast<double>(r.scaling1_fv.Get());
  s.max = static_cast<double>(r.scaling2_fv.Get());
  // Counts, directions and digital states are whole numbers: 2102h applies to Hz, % and rpm.
  const bool has_digits =
      mode == InputMode::kFrequency || mode == InputMode::kPwm ||
      (mode == InputMode::kQuadrature && r.range.Get() == static_cast<std::int64_t>(QuadratureRange::kSpeed));
  s.decimal_digits = has_digits ? static_cast<std::uint8_t>(r.fv_digits.Get()) : 0;
  s.error = c.span.Faulted();
  return s;
}

std::optional<Ms> PulseInputs::NextChange(const std::array<bool, kInputs>& consumed) const {
  std::optional<Ms> next;
  for (int ch = 0; ch < kInputs; ++ch) {
    const Channel& c = channels_[ch];
    if (!c.settled) return kFilterCall;
    const blocks::SpanParams span = Span(ch);
    if (Moving(ch) && (consumed[ch] || span.enabled || Filter(ch).type != blocks::FilterType::kNone))
      return kFilterCall;
    if (c.span.Busy()) {
      const Ms left = std::max(kFilterCall, span.delay - c.span.Held());
      next = next ? std::min(*next, left) : left;
    }
  }
  return next;
}

void PulseInputs::Reset(TimePoint now) {
  for (Channel& c : channels_) {
    c.filter.Reset();
    c.span.Reset();
    c.fv = 0.0;
    c.settled = true;
    c.was_busy = false;
    c.digital = false;
    c.pin_before = false;
    c.response = -1;
    c.high->Reset();
    c.low->Reset();
  }
  last_forward_.reset();
  ZeroCounter(now);
}

void PulseInputs::UpdateVelocity(TimePoint now) {
  const double sign = io_.direction->Is(kReverse) ? -1.0 : 1.0;
  double edges = 0.0;
  if (io_.drive->Is(kDriveCounts)) {
    edges = io_.speed_counts->Number();
  } else if (io_.drive->Is(kDriveChannels)) {
    // Both channels must toggle for the pair to advance: a channel that stops (or runs slower)
    // makes the other one's edges count up and down in turn, which nets nothing.
    edges = 4.0 * std::min(io_.frequency[0]->Number(), io_.frequency[1]->Number());
  } else {
    edges = EdgesPerSecond(io_.speed_rpm->Number(), io_.pulses_per_rev->Number());
  }
  const double velocity = sign * edges;
  shaft_.SetVelocity(now, velocity);
  if (velocity != 0.0) last_forward_ = velocity > 0.0;
}

void PulseInputs::OnSignal(const IoSignal& signal, TimePoint now) {
  if (&signal == io_.position) {
    const double before = shaft_.PositionAt(now);
    const double target = signal.Number();
    shaft_.MoveTo(now, target);
    if (target != before) last_forward_ = target > before;
    return;
  }
  const bool shaft_signal = &signal == io_.drive || &signal == io_.speed_rpm || &signal == io_.speed_counts ||
                            &signal == io_.direction || &signal == io_.pulses_per_rev ||
                            &signal == io_.frequency[0] || &signal == io_.frequency[1];
  if (shaft_signal) UpdateVelocity(now);
}

}  // namespace canfleet::devices::encoder
