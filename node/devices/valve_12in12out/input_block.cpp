#include "node/devices/valve_12in12out/input_block.hpp"

#include <algorithm>
#include <cmath>

#include "node/devices/family/family_error_policy.hpp"

namespace canfleet::devices::valve {

namespace {

using namespace std::chrono_literals;
using blocks::SpanFlag;

constexpr std::chrono::milliseconds kStep{1};

}  // namespace

InputBlock::InputBlock(canopen::CanopenStack& stack, Scheduler& scheduler, const ValveIo& io) : io_(io) {
  auto& od = stack.od();
  for (int ch = 0; ch < kInputs; ++ch) {
    const std::uint8_t sub = SubOf(ch);
    Refs& r = refs_[ch];
    r.type = OdRef(od, kAiSensorType, sub);
    r.mode = OdRef(od, kAiMode, sub);
    r.range = OdRef(od, kAiRange, sub);
    r.ppr = OdRef(od, kAiPulsesPerRev, sub);
    r.digits = OdRef(od, kAiFvDigits, sub);
    r.pull = OdRef(od, kDiPull, sub);
    r.polarity = OdRef(od, kDiPolarity, sub);
    r.error_enable = OdRef(od, kAiErrorEnable, sub);
    r.hysteresis = OdRef(od, kAiErrorHysteresis, sub);
    r.delay = OdRef(od, kAiErrorDelay, sub);
    r.filter_type = OdRef(od, kAiFilterType, sub);
    r.filter_constant = OdRef(od, kAiFilterConstant, sub);
    r.scaling1_fv = OdRef(od, kAiScaling1Fv, sub);
    r.scaling1_pv = OdRef(od, kAiScaling1Pv, sub);
    r.scaling2_fv = OdRef(od, kAiScaling2Fv, sub);
    r.scaling2_pv = OdRef(od, kAiScaling2Pv, sub);
    r.span_start = OdRef(od, kAiSpanStart, sub);
    r.span_end = OdRef(od, kAiSpanEnd, sub);
    r.fv = OdRef(od, kAiFieldValue, sub);
    r.pv = OdRef(od, kAiProcessValue, sub);
    r.state = OdRef(od, kDiReadState, sub);
    r.filter_power = OdRef(od, kAiFilterPower, sub);
    for (int k = 0; k < 4; ++k)
      r.filter_in[k] = OdRef(od, static_cast<std::uint16_t>(kAiFilterIn0 + k), sub);
    for (int k = 0; k < 3; ++k)
      r.filter_out[k] = OdRef(od, static_cast<std::uint16_t>(kAiFilterOut1 + k), sub);
    if (ch < kDiagnosedChannels) {
      Channel& c = channels_[ch];
      c.low = std::make_unique<DelayedFault>(
          scheduler, stack, family::MakeFamilyEntry(kEmcyInputOverload, kDescNegativeOverload, sub),
          kBehaviourAnalogInput);
      c.high = std::make_unique<DelayedFault>(
          scheduler, stack, family::MakeFamilyEntry(kEmcyInputOverload, kDescPositiveOverload, sub),
          kBehaviourAnalogInput);
    }
  }
}

void InputBlock::StartOver(Channel& c) {
  c.analog.Reset();
  c.has_last = false;
  c.state = false;
  c.latch_seen = false;
  if (c.low) c.low->Update(false, Duration::zero());
  if (c.high) c.high->Update(false, Duration::zero());
}

void InputBlock::Reset() {
  for (Channel& c : channels_) {
    c.analog.Reset();
    c.has_last = false;
    c.key = Key{};
    c.state = false;
    c.latch_seen = false;
    if (c.low) c.low->Reset();
    if (c.high) c.high->Reset();
  }
}

blocks::AnalogInputParams InputBlock::ReadParams(int ch) const {
  const Refs& r = refs_[ch];
  blocks::AnalogInputParams p;
  const auto code = static_cast<std::uint8_t>(r.filter_type.Get());
  p.filter.type = blocks::DecodeFilterType(code, true).value_or(blocks::FilterType::kNone);
  p.filter.constant = static_cast<std::uint16_t>(std::clamp<std::int64_t>(r.filter_constant.Get(), 1, 1000));
  if (p.filter.type == blocks::FilterType::kThirdOrderLowPass) {
    for (int k = 0; k < 4; ++k)
      p.filter.third_order.input[k] = static_cast<std::int32_t>(r.filter_in[k].Get());
    for (int k = 0; k < 3; ++k)
      p.filter.third_order.output[k] = static_cast<std::int32_t>(r.filter_out[k].Get());
    p.filter.third_order.power =
        static_cast<std::uint8_t>(std::clamp<std::int64_t>(r.filter_power.Get(), 0, 16));
  }
  p.fv_digits = static_cast<std::uint8_t>(std::clamp<std::int64_t>(r.digits.Get(), 0, 4));
  p.scaling1_fv = static_cast<double>(r.scaling1_fv.Get());
  p.scaling1_pv = static_cast<double>(r.scaling1_pv.Get());
  p.scaling2_fv = static_cast<double>(r.scaling2_fv.Get());
  p.scaling2_pv = static_cast<double>(r.scaling2_pv.Get());
  p.span.enabled = r.error_enable.Get() != 0;
  p.span.span_start = static_cast<double>(r.span_start.Get());
  p.span.span_end = static_cast<double>(r.span_end.Get());
  p.span.hysteresis = static_cast<double>(r.hysteresis.Get());
  p.span.delay = std::chrono::milliseconds(r.delay.Get());
  return p;
}

double InputBlock::Measure(int ch, const Key& key) const {
  const auto number = [](const IoSignal* s) { return s ? s->Number() : 0.0; };
  switch (static_cast<SensorType>(key.type)) {
    case SensorType::kVoltage:
      return number(io_.voltage[ch]) / 1000.0;  // V
    case SensorType::kCurrent:
      return number(io_.current[ch]);  // mA
    case SensorType::kResistive:
      return number(io_.resistance[ch]) / 1000.0;  // kOhm (FV 0.01 kOhm with 2 digits)
    case SensorType::kFrequency: {
      const double hz = number(io_.frequency[ch]);
      if (!key.rpm) return hz;
      return hz * 60.0 / static_cast<double>(refs_[ch].ppr.Get());  // RPM (FV 0.1 RPM with 1 digit)
    }
    case SensorType::kPwm:
      return number(io_.duty[ch]);  // %
  }
  return 0.0;
}

bool InputBlock::PinHigh(int ch) const {
  const IoSignal& level = *io_.level[ch];
  if (level.Is(kLevelHigh)) return true;
  if (level.Is(kLevelLow)) return false;
  return refs_[ch].pull.Get() == static_cast<std::int64_t>(DiPull::kPullUp);  // open: the pull decides
}

void InputBlock::RunDigital(int ch) {
  Channel& c = channels_[ch];
  const bool high = PinHigh(ch);
  switch (static_cast<DiPolarity>(refs_[ch].polarity.Get())) {
    case DiPolarity::kNormal:
      c.state = high;
      break;
    case DiPolarity::kInverse:
      c.state = !high;
      break;
    case DiPolarity::kLatched:
      if (c.latch_seen && high && !c.latch_raw) c.state = !c.state;  // LOW -> HIGH toggles
      break;
  }
  c.latch_raw = high;
  c.latch_seen = true;
}

void InputBlock::RunAnalog(int ch, std::chrono::milliseconds elapsed) {
  Channel& c = channels_[ch];
  const blocks::AnalogInputParams params = ReadParams(ch);
  const double measured = Measure(ch, c.key);
  if (c.has_last && elapsed > kStep) c.analog.Tick(elapsed - kStep, c.params, c.measured);
  c.analog.Tick(kStep, params, measured);
  c.params = params;
  c.measured = measured;
  c.has_last = true;

  if (c.mode == InputMode::kAnalogOnOff) {
    // Figure 5 (lost): ON at or above 7122h, OFF at or below 7120h, held in between.
    if (c.analog.FieldValue() >= params.scaling2_fv)
      c.state = true;
    else if (c.analog.FieldValue() <= params.scaling1_fv)
      c.state = false;
  } else {
    c.state = false;
  }
  if (c.low) c.low->Update(c.analog.span().Fault() == SpanFlag::kLow, Duration::zero());
  if (c.high) c.high->Update(c.analog.span().Fault() == SpanFlag::kHigh, Duration::zero());
}

void InputBlock::Run(std::chrono::milliseconds elapsed) {
  for (int ch = 0; ch < kInputs; ++ch) {
    Refs& r = refs_[ch];
    Channel& c = channels_[ch];
    Key key{r.type.Get(), r.range.Get(), r.mode.Get(), r.ppr.Get() != 0};
    if (!(key == c.key)) {
      StartOver(c);
      c.key = key;
    }
    c.mode = static_cast<InputMode>(key.mode);
    switch (c.mode) {
      case InputMode::kDigital:
        RunDigital(ch);
        r.fv.Set(c.state ? 1 : 0);
        r.pv.Set(c.state ? 1 : 0);
        break;
      case InputMode::kNormal:
      case InputMode::kAnalogOnOff:
        RunAnalog(ch, elapsed);
        r.fv.SetNumber(c.analog.FieldValue());  // saturated to INTEGER16
        r.pv.SetNumber(c.analog.ProcessValue());
        break;
      default:  // off (or a mode a stored file brought in unchecked)
        c.state = false;
        r.fv.Set(0);
        r.pv.Set(0);
        break;
    }
    r.state.Set(c.state ? 1 : 0);
  }
}

std::optional<std::chrono::milliseconds> InputBlock::NextWake() const {
  std::optional<std::chrono::milliseconds> wake;
  const auto earliest = [&wake](std::chrono::milliseconds t) { wake = wake ? std::min(*wake, t) : t; };
  for (const Channel& c : channels_) {
    if (!c.has_last || (c.mode != InputMode::kNormal && c.mode != InputMode::kAnalogOnOff)) continue;
    if (!c.analog.Busy()) continue;
    const double in = c.measured * blocks::PowerOfTen(c.params.fv_digits);
    if (!c.analog.filter().Settled(c.params.filter, in)) {
      earliest(kStep);
    } else if (c.analog.span().Busy()) {
      earliest(std::max(kStep, c.params.span.delay - c.analog.span().Held()));
    }
  }
  return wake;
}

blocks::Signal InputBlock::AsSource(int ch) const {
  const Channel& c = channels_[ch];
  const Refs& r = refs_[ch];
  switch (c.mode) {
    case InputMode::kDigital: {
      blocks::Signal s;
      s.value = c.state ? 1.0 : 0.0;
      s.min = static_cast<double>(r.scaling1_fv.Get());
      s.max = static_cast<double>(r.scaling2_fv.Get());
      s.decimal_digits = static_cast<std::uint8_t>(std::clamp<std::int64_t>(r.digits.Get(), 0, 4));
      return s;
    }
    case InputMode::kNormal:
    case InputMode::kAnalogOnOff: {
      blocks::Signal s = c.analog.AsSource(c.params);
      // Limits as configured now (a write of 7120h/7122h applies before the next run).
      s.min = static_cast<double>(r.scaling1_fv.Get());
      s.max = static_cast<double>(r.scaling2_fv.Get());
      return s;
    }
    default:
      return blocks::Signal::NotAvailable();
  }
}

}  // namespace canfleet::devices::valve
