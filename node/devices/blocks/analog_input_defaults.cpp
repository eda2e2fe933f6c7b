#include "node/devices/blocks/analog_input_defaults.hpp"

#include <array>

namespace canfleet::devices::blocks {
namespace {

using R = InputRange;

// UMAX020411A Table 10 (values) and Table 9 (digits), printed order. The 0-20 mA row is kept as
// printed (see the header).
constexpr std::array<InputDefaults, 9> kValve{{
    {R::kVoltage0To5V, 3, 200, 500, 4500, 4800, 100},
    {R::kVoltage0To10V, 3, 200, 500, 9500, 9800, 200},
    {R::kCurrent0To20mA, 0, 0, 0, 30000, 32000, 250},
    {R::kCurrent4To20mA, 0, 3, 4, 20, 21, 1},
    {R::kResistive, 2, 2, 10, 20000, 25000, 1},
    {R::kFrequency, 0, 100, 150, 30000, 32000, 5},
    {R::kRpm, 1, 500, 1000, 30000, 33000, 100},
    {R::kPwm, 1, 10, 50, 950, 990, 1},
    {R::kDigital, 0, 0, 0, 1, 1, 0},  // "OFF OFF ON ON 0"
}};

// UMAX181001 Table 11 (values) and Table 10 (digits); no resistive input.
constexpr std::array<InputDefaults, 8> kDataLogger{{
    {R::kVoltage0To5V, 3, 200, 500, 4500, 4800, 100},
    {R::kVoltage0To10V, 3, 200, 500, 9500, 9800, 200},
    {R::kCurrent0To20mA, 0, 0, 0, 20, 21, 1},
    {R::kCurrent4To20mA, 0, 3, 4, 20, 21, 1},
    {R::kFrequency, 0, 100, 150, 30000, 32000, 5},
    {R::kRpm, 1, 500, 1000, 30000, 33000, 100},
    {R::kPwm, 1, 10, 50, 950, 990, 1},  // hysteresis printed "110.1%]" = 1 [0.1 %]
    {R::kDigital, 0, 0, 0, 1, 1, 0},
}};

}  // namespace

std::optional<InputRange> ClassifyInput(std::uint16_t sensor_type, std::uint8_t range, bool rpm,
                                        bool digital) {
  if (digital) return R::kDigital;
  switch (sensor_type) {
    case 40:
      if (range == 0) return R::kVoltage0To5V;
      if (range == 1) return R::kVoltage0To10V;
      return std::nullopt;
    case 50:
      if (range == 0) return R::kCurrent0To20mA;
      if (range == 1) return R::kCurrent4To20mA;
      return std::nullopt;
    case 60:
      if (range != 0) return std::nullopt;
      return rpm ? R::kRpm : R::kFrequency;
    case 10000:
      return range == 0 ? std::optional<InputRange>(R::kPwm) : std::nullopt;
    case 11000:
      return range == 0 ? std::optional<InputRange>(R::kResistive) : std::nullopt;
    default:
      return std::nullopt;
  }
}

std::span<const InputDefaults> ValveInputDefaults() {
  return kValve;
}
std::span<const InputDefaults> DataLoggerInputDefaults() {
  return kDataLogger;
}

std::optional<InputDefaults> FindInputDefaults(std::span<const InputDefaults> table, InputRange range) {
  for (const InputDefaults& row : table) {
    if (row.range == range) return row;
  }
  return std::nullopt;
}

}  // namespace canfleet::devices::blocks
