#pragma once
/// @file Which simulated signal of an input pin the family's configuration reads (the Quad, the
/// valve controller, the encoder controller and the data logger configure every input the same
/// way): 6112h operating mode 0 off, 1 normal and 20 analog on/off measure what 6110h's sensor type
/// names (40/42 voltage, 50/51/52 current, 11000 resistance, 60 frequency, 10000 PWM duty), 10
/// digital reads the pin's level. A pin is one channel `IN<n>` with one signal per quantity
/// (node/devices/README.md "Signals"); setting a quantity the configuration does not read is
/// accepted and answered with this notice, never silently ignored.

#include <cstdint>
#include <string>

#include "node/devices/simulated_io.hpp"

namespace canfleet::devices::family {

/// One input pin: its channel, its sub-index in 6110h/6112h, their present values and its signals
/// (null where the pin lacks the quantity).
struct InputPin {
  std::string channel;  ///< "IN2"
  std::uint8_t sub = 0;
  std::int64_t sensor_type = 0;  ///< 6110h
  std::int64_t mode = 0;         ///< 6112h
  const IoSignal* voltage = nullptr;
  const IoSignal* current = nullptr;
  const IoSignal* resistance = nullptr;
  const IoSignal* frequency = nullptr;
  const IoSignal* duty = nullptr;
  const IoSignal* level = nullptr;

  bool Has(const IoSignal& signal) const;
};

/// The signal the configuration reads; null when it reads none (off, or a type with no signal of
/// its own such as the encoder's quadrature decoding).
const IoSignal* ReadSignal(const InputPin& pin);

/// "" when `input` is not the pin's or is the signal read; else IgnoredNotice's line naming 6112h
/// and 6110h and what the pin reads.
std::string IgnoredInput(const IoSignal& input, const InputPin& pin);

}  // namespace canfleet::devices::family
