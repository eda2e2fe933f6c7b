#include "node/devices/family/input_config.hpp"

namespace canfleet::devices::family {

bool InputPin::Has(const IoSignal& signal) const {
  for (const IoSignal* s : {voltage, current, resistance, frequency, duty, level})
    if (s == &signal) return true;
  return false;
}

const IoSignal* ReadSignal(const InputPin& pin) {
  if (pin.mode == 10) return pin.level;
  if (pin.mode != 1 && pin.mode != 20) return nullptr;
  switch (pin.sensor_type) {
    case 40:
    case 42:
      return pin.voltage;
    case 50:
    case 51:
    case 52:
      return pin.current;
    case 11000:
      return pin.resistance;
    case 60:
      return pin.frequency;
    case 10000:
      return pin.duty;
    default:
      return nullptr;
  }
}

std::string IgnoredInput(const IoSignal& input, const InputPin& pin) {
  if (!pin.Has(input)) return {};
  const IoSignal* read = ReadSignal(pin);
  if (read == &input) return {};
  const std::string sub = std::to_string(pin.sub);
  return IgnoredNotice(
      input,
      pin.channel + "'s configuration (6112h sub " + sub + " = " + std::to_string(pin.mode) + ", 6110h sub " +
          sub + " = " + std::to_string(pin.sensor_type) + ")",
      read != nullptr ? "it reads " + read->name() : std::string("it reads none of the pin's signals"));
}

}  // namespace canfleet::devices::family
