#pragma once
/// @file The dependent-object auto-update table of the analog input (5550h TRUE: writing 6110h
/// or 2100h reloads 2102h, 7148h, 7120h, 7122h, 7149h and 2111h). Valve UMAX020411A Tables 9 and
/// 10; logger UMAX181001 Tables 10 and 11. The encoder manual (AX023241 §1.2) says the objects
/// are updated but gives no values, so it has no table here.
///
/// Values are in field-value units (with the row's digits). Where the two manuals differ:
/// - 0-20 mA: the valve prints 0 / 0 / 30000 / 32000 / 250 "[mA]" with 0 digits, which cannot be
///   mA (2111h would exceed its own "10 % of MAX" limit, Table 11); the logger prints
///   0 / 0 / 20 / 21 / 1 mA. Each product keeps its own manual's row (README.md).
/// - resistive (0.01 kOhm, 2 digits) exists on the valve only.
///
/// Tick order and loop rule: see signal.hpp (inputs -> math -> LUT -> logic -> PID -> outputs; a
/// block reading itself or a later block sees the previous tick).

#include <cstdint>
#include <optional>
#include <span>

namespace canfleet::devices::blocks {

/// Sensor type x range combinations of Table 10.
enum class InputRange : std::uint8_t {
  kVoltage0To5V,
  kVoltage0To10V,
  kCurrent0To20mA,
  kCurrent4To20mA,
  kResistive,
  kFrequency,
  kRpm,
  kPwm,
  kDigital,
};

struct InputDefaults {
  InputRange range;
  std::uint8_t fv_digits;   ///< 2102h (Table 9)
  std::int32_t span_start;  ///< 7148h
  std::int32_t scaling1;    ///< 7120h (and 7121h: PV = FV by default)
  std::int32_t scaling2;    ///< 7122h (and 7123h)
  std::int32_t span_end;    ///< 7149h
  std::int32_t hysteresis;  ///< 2111h
};

/// The Table 10 row for 6110h `sensor_type` (40 V, 50 mA, 60 Hz, 10000 PWM, 11000 resistive),
/// 2100h `range` (V: 0 = 0-5 V, 1 = 0-10 V; mA: 0 = 0-20, 1 = 4-20), 2101h pulses per rev != 0
/// (`rpm`) and 6112h = 10 (`digital`). nullopt for combinations Table 6 does not allow.
std::optional<InputRange> ClassifyInput(std::uint16_t sensor_type, std::uint8_t range, bool rpm,
                                        bool digital);

/// Valve Table 10 (with Table 9 digits).
std::span<const InputDefaults> ValveInputDefaults();
/// Logger Table 11 (with Table 10 digits).
std::span<const InputDefaults> DataLoggerInputDefaults();

/// The row of `range` in `table`, if the product has it.
std::optional<InputDefaults> FindInputDefaults(std::span<const InputDefaults> table, InputRange range);

}  // namespace canfleet::devices::blocks
