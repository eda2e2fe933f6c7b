#include "node/devices/datalogger_tc_analog/analog_block.hpp"

#include <algorithm>
#include <cmath>

#include "node/devices/datalogger_tc_analog/analog_config.hpp"
#include "node/devices/family/family_error_policy.hpp"
#include "node/devices/family/input_config.hpp"

namespace canfleet::devices::datalogger {

namespace {

bool Analog(std::int64_t mode) {
  return mode == kModeNormal || mode == kModeAnalogOnOff;
}

}  // namespace

AnalogInputBlock::AnalogInputBlock(canopen::ObjectDictionary& od, const DataLoggerIo& io,
                                   Scheduler& scheduler, std::span<canopen::CanopenStack* const> stacks)
    : od_(od), io_(io), auto_updates_(od, kAutoUpdates, 0) {
  for (int ch = 0; ch < kAnalogInputs; ++ch) {
    Channel& c = channels_[static_cast<std::size_t>(ch)];
    const std::uint8_t sub = SubOf(ch);
    c.mode = OdRef(od, kAiOperatingMode, sub);
    c.type = OdRef(od, kSensorType, sub);
    c.range = OdRef(od, kAiRange, sub);
    c.pulses = OdRef(od, kAiPulsesPerRev, sub);
    c.fv_digits = OdRef(od, kAiFvDigits, sub);
    c.filter_type = OdRef(od, kAiFilterType, sub);
    c.filter_constant = OdRef(od, kAiFilterConstant, sub);
    c.filter_power = OdRef(od, kAiFilterPower, sub);
    for (std::size_t k = 0; k < c.filter_in.size(); ++k)
      c.filter_in[k] = OdRef(od, static_cast<std::uint16_t>(kAiFilterInput0 + k), sub);
    for (std::size_t k = 0; k < c.filter_out.size(); ++k)
      c.filter_out[k] = OdRef(od, static_cast<std::uint16_t>(kAiFilterOutput1 + k), sub);
    c.scaling1_fv = OdRef(od, kAiScaling1Fv, sub);
    c.scaling1_pv = OdRef(od, kAiScaling1Pv, sub);
    c.scaling2_fv = OdRef(od, kAiScaling2Fv, sub);
    c.scaling2_pv = OdRef(od, kAiScaling2Pv, sub);
    c.span_start = OdRef(od, kAiSpanStart, sub);
    c.span_end = OdRef(od, kAiSpanEnd, sub);
    c.error_enable = OdRef(od, kAiErrorEnable, sub);
    c.hysteresis = OdRef(od, kAiErrorHysteresis, sub);
    c.delay = OdRef(od, kAiErrorDelay, sub);
    c.polarity = OdRef(od, kDiPolarity, sub);
    c.pullup = OdRef(od, kDiPullup, sub);
    c.field_value = OdRef(od, kAiFieldValue, sub);
    c.process_value = OdRef(od, kAiProcessValue, sub);
    c.di_state = OdRef(od, kDiState, sub);
    // Table 26: 20h positive / 40h negative overload, channel = input number; 1029h sub 3 for
    // inputs 1-7 only (§1.4).
    const std::uint8_t reaction = ch + 1 < kFirstUniversal ? kBehaviourInputFault : 0;
    c.high = std::make_unique<DeviceFault>(
        scheduler, stacks, family::MakeFamilyEntry(kEmcyInputOverload, kDescPositiveOverload, sub), reaction);
    c.low = std::make_unique<DeviceFault>(
        scheduler, stacks, family::MakeFamilyEntry(kEmcyInputOverload, kDescNegativeOverload, sub), reaction);
  }
  Latch();
  RefreshClasses();
}

void AnalogInputBlock::Latch() {
  for (int ch = 0; ch < kAnalogInputs; ++ch) {
    Channel& c = channels_[static_cast<std::size_t>(ch)];
    const int input = ch + 1;
    c.pins.voltage_mv = io_.ain_voltage[static_cast<std::size_t>(ch)]->Number();
    c.pins.current_ma = io_.ain_current[static_cast<std::size_t>(ch)]->Number();
    if (input >= kFirstPulseInput && input < kFirstPulseInput + kPulseInputs) {
      const auto p = static_cast<std::size_t>(input - kFirstPulseInput);
      c.pins.frequency_hz = io_.ain_frequency[p]->Number();
      c.pins.duty_pct = io_.ain_duty[p]->Number();
    }
    if (input >= kFirstUniversal) {
      const IoSignal& level = *io_.din_level[static_cast<std::size_t>(input - kFirstUniversal)];
      // "LOW or Open" reads OFF without the pull-up (Table 4); the pull-up makes open HIGH (Table 2).
      c.pins.level_high = level.Is(kLevelHigh) || (level.Is(kLevelOpen) && c.pullup.Get() != 0);
    }
    // Table 4, latched logic: a LOW->HIGH change toggles the state, HIGH->LOW changes nothing.
    if (c.mode.Get() == kModeDigital && c.polarity.Get() == 2 && c.pins.level_high && !c.level_high_before)
      c.latched_state = !c.latched_state;
    c.level_high_before = c.pins.level_high;
  }
}

blocks::AnalogInputParams AnalogInputBlock::ParamsOf(const Channel& c) const {
  blocks::AnalogInputParams p;
  p.filter.type = blocks::DecodeFilterType(static_cast<std::uint8_t>(c.filter_type.Get()), true)
                      .value_or(blocks::FilterType::kNone);
  p.filter.constant = static_cast<std::uint16_t>(std::clamp<std::int64_t>(c.filter_constant.Get(), 1, 1000));
  for (std::size_t k = 0; k < c.filter_in.size(); ++k)
    p.filter.third_order.input[k] = static_cast<std::int32_t>(c.filter_in[k].Get());
  for (std::size_t k = 0; k < c.filter_out.size(); ++k)
    p.filter.third_order.output[k] = static_cast<std::int32_t>(c.filter_out[k].Get());
  p.filter.third_order.power =
      static_cast<std::uint8_t>(std::clamp<std::int64_t>(c.filter_power.Get(), 0, 16));
  p.fv_digits = static_cast<std::uint8_t>(std::clamp<std::int64_t>(c.fv_digits.Get(), 0, 4));
  p.scaling1_fv = static_cast<double>(c.scaling1_fv.Get());
  p.scaling1_pv = static_cast<double>(c.scaling1_pv.Get());
  p.scaling2_fv = static_cast<double>(c.scaling2_fv.Get());
  p.scaling2_pv = static_cast<double>(c.scaling2_pv.Get());
  p.span.enabled = c.error_enable.Get() != 0 && Analog(c.mode.Get());
  p.span.span_start = static_cast<double>(c.span_start.Get());
  p.span.span_end = static_cast<double>(c.span_end.Get());
  p.span.hysteresis = static_cast<double>(c.hysteresis.Get());
  p.span.delay = std::chrono::milliseconds{c.delay.Get()};
  return p;
}

std::string AnalogInputBlock::IgnoredInput(const IoSignal& input) const {
  // §1.4, §3.3.4/§3.3.5: the family's rule (6112h, 6110h), family/input_config.hpp.
  for (int ch = 0; ch < kAnalogInputs; ++ch) {
    const auto i = static_cast<std::size_t>(ch);
    const Channel& c = channels_[i];
    const int input_no = ch + 1;
    const bool pulse = input_no >= kFirstPulseInput && input_no < kFirstPulseInput + kPulseInputs;
    const auto p = static_cast<std::size_t>(input_no - kFirstPulseInput);
    family::InputPin pin{.channel = "IN" + std::to_string(input_no),
                         .sub = static_cast<std::uint8_t>(input_no),
                         .sensor_type = c.type.Get(),
                         .mode = c.mode.Get(),
                         .voltage = io_.ain_voltage[i],
                         .current = io_.ain_current[i],
                         .frequency = pulse ? io_.ain_frequency[p] : nullptr,
                         .duty = pulse ? io_.ain_duty[p] : nullptr,
                         .level = input_no >= kFirstUniversal
                                      ? io_.din_level[static_cast<std::size_t>(input_no - kFirstUniversal)]
                                      : nullptr};
    if (pin.Has(input)) return family::IgnoredInput(input, pin);
  }
  return {};
}

double AnalogInputBlock::Measured(const Channel& c) const {
  switch (c.type.Get()) {
    case kSensorVoltage:
      return c.pins.voltage_mv / 1000.0;
    case kSensorCurrent:
      return c.pins.current_ma;
    case kSensorFrequency: {
      // §3.4.5: a non-zero pulses-per-revolution turns the Hz reading into rpm.
      const auto pulses = c.pulses.Get();
      return pulses != 0 ? c.pins.frequency_hz * 60.0 / static_cast<double>(pulses) : c.pins.frequency_hz;
    }
    case kSensorPwm:
      return c.pins.duty_pct;
    default:
      return 0.0;
  }
}

bool AnalogInputBlock::DigitalState(const Channel& c) const {
  switch (c.polarity.Get()) {
    case 1:
      return !c.pins.level_high;
    case 2:
      return c.latched_state;
    default:
      return c.pins.level_high;
  }
}

void AnalogInputBlock::Advance(std::chrono::milliseconds elapsed) {
  for (Channel& c : channels_) {
    if (!Analog(c.mode.Get())) {
      c.ai.Reset();  // starts from 0 when the input becomes analog again
      continue;
    }
    c.ai.Tick(elapsed, ParamsOf(c), Measured(c));
  }
}

void AnalogInputBlock::Publish() {
  for (Channel& c : channels_) {
    const std::int64_t mode = c.mode.Get();
    blocks::SpanFlag fault = blocks::SpanFlag::kNone;
    bool state = false;
    if (Analog(mode)) {
      c.field_value.SetNumber(c.ai.FieldValue());
      c.process_value.SetNumber(c.ai.ProcessValue());
      fault = c.ai.span().Fault();
      if (mode == kModeAnalogOnOff) {
        const double fv = c.ai.FieldValue();
        if (fv >= static_cast<double>(c.scaling2_fv.Get()))
          c.on_off_state = true;
        else if (fv <= static_cast<double>(c.scaling1_fv.Get()))
          c.on_off_state = false;
        state = c.on_off_state;
      }
    } else if (mode == kModeDigital) {
      state = DigitalState(c);
      const double fv = state ? 1.0 : 0.0;
      c.field_value.SetNumber(fv);
      c.process_value.SetNumber(blocks::ScaleToProcessValue(ParamsOf(c), fv));
    } else {
      c.field_value.Set(0);
      c.process_value.Set(0);
    }
    if (mode != kModeAnalogOnOff) c.on_off_state = false;
    c.di_state.Set(state ? 1 : 0);
    c.high->Set(fault == blocks::SpanFlag::kHigh);
    c.low->Set(fault == blocks::SpanFlag::kLow);
  }
}

bool AnalogInputBlock::Settling() const {
  for (const Channel& c : channels_) {
    if (!Analog(c.mode.Get())) continue;
    const blocks::AnalogInputParams p = ParamsOf(c);
    if (!c.ai.filter().Settled(p.filter, Measured(c) * blocks::PowerOfTen(p.fv_digits))) return true;
  }
  return false;
}

std::optional<std::chrono::milliseconds> AnalogInputBlock::NextDelayEnd() const {
  std::optional<std::chrono::milliseconds> next;
  for (const Channel& c : channels_) {
    if (!Analog(c.mode.Get()) || !c.ai.span().Busy()) continue;
    const auto remaining =
        std::max(std::chrono::milliseconds{0}, std::chrono::milliseconds{c.delay.Get()} - c.ai.span().Held());
    if (!next || remaining < *next) next = remaining;
  }
  return next;
}

blocks::Signal AnalogInputBlock::Source(int ch) const {
  const Channel& c = channels_.at(static_cast<std::size_t>(ch));
  const std::int64_t mode = c.mode.Get();
  if (mode == kModeDigital || mode == kModeAnalogOnOff) {
    blocks::Signal s;
    s.value = static_cast<double>(c.di_state.Get());
    s.min = 0;
    s.max = 1;
    return s;
  }
  if (mode == kModeOff) {
    blocks::Signal s;
    s.min = static_cast<double>(c.scaling1_fv.Get());
    s.max = static_cast<double>(c.scaling2_fv.Get());
    s.decimal_digits = static_cast<std::uint8_t>(c.fv_digits.Get());
    return s;
  }
  return c.ai.AsSource(ParamsOf(c));
}

void AnalogInputBlock::OnConfigWritten(int ch, bool sensor_type_written) {
  Channel& c = channels_.at(static_cast<std::size_t>(ch));
  const bool automatic = auto_updates_.Get() != 0;
  const auto type = c.type.Get();
  if (automatic && sensor_type_written && type != c.sensor_type) {
    c.range.Set(0);
    if (type != kSensorFrequency && type != kSensorPwm) c.pullup.Set(0);
  }
  c.sensor_type = type;
  const auto input_class = ClassifyChannel(od_, ch);
  if (input_class == c.input_class) return;
  c.input_class = input_class;
  if (automatic && input_class) ApplyInputDefaults(od_, ch, *input_class);
}

void AnalogInputBlock::RefreshClasses() {
  for (int ch = 0; ch < kAnalogInputs; ++ch) {
    Channel& c = channels_[static_cast<std::size_t>(ch)];
    c.input_class = ClassifyChannel(od_, ch);
    c.sensor_type = c.type.Get();
  }
}

void AnalogInputBlock::Reset() {
  Latch();  // the pins as they are now; a level already HIGH is no edge
  for (Channel& c : channels_) {
    c.ai.Reset();
    c.latched_state = false;
    c.on_off_state = false;
  }
  RefreshClasses();
}

void AnalogInputBlock::ResetPort(std::size_t port) {
  for (Channel& c : channels_) {
    c.high->ResetPort(port);
    c.low->ResetPort(port);
  }
}

}  // namespace canfleet::devices::datalogger
