#pragma once
/// @file What a valve input accepts and how its field-value objects are bounded (UMAX020411A §1.3
/// Tables 4-6 and 9-11, §1.1 and §4 for which pin measures what).
///
/// - Accepted 6110h per pin (Table 5 values, §1.1 capabilities): UI1-6 voltage, current, resistive;
///   UI1, 3, 5 also frequency and PWM; UI7 voltage, current, frequency, PWM (no resistive); DI1, 3, 5
///   frequency and PWM; DI2, DI4 PWM only (their factory value: the pins are digital only, 6110h
///   means nothing there). Accepted 6112h (Table 4): 0, 1, 10, 20; DI2/DI4 only 0 or 10 ("Digital
///   Input 2 and 4 cannot be set to other values"; §4 lists "Disable input" for every DI).
/// - Accepted 2100h (Table 6): voltage 0 (0-5 V) or 1 (0-10 V), current 0 (0-20 mA) or 1
///   (4-20 mA), others 0.
/// - Table 11 in field-value units (base unit x 10^2102h): MAX is the top of the range (5 V, 10 V,
///   20 mA, 250 kOhm, 50 kHz, 6000 RPM, 100 %, digital 1), 7149h up to 110 % of MAX, 2111h up to 10 %
///   of MAX; 7120h has the floors 4 mA (4-20 mA), 20 Ohm (resistive), 0.5 Hz (frequency); 7148h
///   starts at 0.1 Hz for frequency. Ends beyond INTEGER16 are held at its limits.
/// - Table 10 (the 5550h auto-update rows) from blocks::ValveInputDefaults(), except 0-20 mA: the
///   printed row (0 / 0 / 30000 / 32000 / 250 mA) breaks Table 11 (7122h <= MAX = 20 mA, 2111h <=
///   2 mA) and would refuse every later 7149h write; the valve uses 0 / 0 / 20 / 21 / 1 mA, the
///   4-20 mA row's pattern (README.md).

#include <cstdint>
#include <optional>

#include "node/devices/blocks/analog_input_defaults.hpp"

namespace canfleet::devices::valve {

bool SensorTypeAllowed(int input, std::uint16_t sensor_type);
bool InputModeAllowed(int input, std::uint8_t mode);
bool InputRangeAllowed(std::uint16_t sensor_type, std::uint8_t range);

/// The Table 10 class of an input configuration; an invalid 2100h (possible with 5550h FALSE) is
/// read as range 0. nullopt for a sensor type Table 5 does not have.
std::optional<blocks::InputRange> ClassifyValveInput(std::uint16_t sensor_type, std::uint8_t range,
                                                     std::uint16_t pulses_per_rev, std::uint8_t mode);

/// The valve's Table 10 row (with Table 9 digits) for `range`.
blocks::InputDefaults ValveDefaultsFor(blocks::InputRange range);

/// Table 11 bounds of one input in its field-value units (`digits` = 2102h).
struct InputBounds {
  double max = 0;              ///< MAX
  double span_start_low = 0;   ///< 7148h >= this
  double scaling1_floor = 0;   ///< 7120h >= max(7148h, this)
  double span_end_high = 0;    ///< 7149h <= 110 % of MAX
  double hysteresis_high = 0;  ///< 2111h <= 10 % of MAX
};
InputBounds BoundsFor(blocks::InputRange range, std::uint8_t digits);

}  // namespace canfleet::devices::valve
