#include "node/devices/valve_12in12out/input_ranges.hpp"

#include <algorithm>
#include <cmath>

#include "node/devices/blocks/signal.hpp"
#include "node/devices/valve_12in12out/valve_io.hpp"
#include "node/devices/valve_12in12out/valve_objects.hpp"

namespace canfleet::devices::valve {

using blocks::InputRange;

bool SensorTypeAllowed(int input, std::uint16_t sensor_type) {
  switch (static_cast<SensorType>(sensor_type)) {
    case SensorType::kVoltage:
    case SensorType::kCurrent:
      return HasVoltage(input);
    case SensorType::kResistive:
      return HasResistance(input);
    case SensorType::kFrequency:
      return HasPulse(input);
    case SensorType::kPwm:
      // DI2/DI4 keep their factory 10000 (the value means nothing on a digital-only pin).
      return HasPulse(input) || input >= kUniversalInputs;
  }
  return false;
}

bool InputModeAllowed(int input, std::uint8_t mode) {
  const bool digital_only = input >= kUniversalInputs && !HasPulse(input);
  switch (static_cast<InputMode>(mode)) {
    case InputMode::kOff:
    case InputMode::kDigital:
      return true;
    case InputMode::kNormal:
    case InputMode::kAnalogOnOff:
      return !digital_only;
  }
  return false;
}

bool InputRangeAllowed(std::uint16_t sensor_type, std::uint8_t range) {
  const auto type = static_cast<SensorType>(sensor_type);
  if (type == SensorType::kVoltage || type == SensorType::kCurrent) return range <= 1;
  return range == 0;
}

std::optional<InputRange> ClassifyValveInput(std::uint16_t sensor_type, std::uint8_t range,
                                             std::uint16_t pulses_per_rev, std::uint8_t mode) {
  const std::uint8_t r = InputRangeAllowed(sensor_type, range) ? range : 0;
  return blocks::ClassifyInput(sensor_type, r, pulses_per_rev != 0,
                               mode == static_cast<std::uint8_t>(InputMode::kDigital));
}

blocks::InputDefaults ValveDefaultsFor(InputRange range) {
  if (range == InputRange::kCurrent0To20mA) return {InputRange::kCurrent0To20mA, 0, 0, 0, 20, 21, 1};
  if (auto row = blocks::FindInputDefaults(blocks::ValveInputDefaults(), range)) return *row;
  return {range, 0, 0, 0, 1, 1, 0};
}

InputBounds BoundsFor(InputRange range, std::uint8_t digits) {
  // MAX and the floors in the input's base unit (Table 9: V, mA, kOhm, Hz, RPM, %, on/off).
  double max = 1;
  double span_start_low = 0;
  double scaling1_floor = 0;
  switch (range) {
    case InputRange::kVoltage0To5V:
      max = 5;
      break;
    case InputRange::kVoltage0To10V:
      max = 10;
      break;
    case InputRange::kCurrent0To20mA:
      max = 20;
      break;
    case InputRange::kCurrent4To20mA:
      max = 20;
      scaling1_floor = 4;
      break;
    case InputRange::kResistive:
      max = 250;
      scaling1_floor = 0.02;
      break;
    case InputRange::kFrequency:
      max = 50000;
      span_start_low = 0.1;
      scaling1_floor = 0.5;
      break;
    case InputRange::kRpm:
      max = 6000;
      break;
    case InputRange::kPwm:
      max = 100;
      break;
    case InputRange::kDigital:
      max = 1;
      break;
  }
  const double scale = blocks::PowerOfTen(digits);
  const auto fv = [scale](double base) { return std::clamp(base * scale, -32768.0, 32767.0); };
  InputBounds b;
  b.max = fv(max);
  // Floors below one FV unit round up to it (0.5 Hz with 0 digits = 1 Hz); 0.1 Hz at 0 digits is 0.
  b.span_start_low = span_start_low * scale >= 1 ? std::ceil(fv(span_start_low)) : 0;
  b.scaling1_floor = scaling1_floor > 0 ? std::max(1.0, std::ceil(fv(scaling1_floor))) : 0;
  b.span_end_high = std::floor(fv(max * 1.1));
  b.hysteresis_high = std::floor(fv(max * 0.1));
  return b;
}

}  // namespace canfleet::devices::valve
