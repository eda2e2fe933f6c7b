#include "node/devices/encoder_dual_valve/input_defaults.hpp"

#include <array>

#include "node/devices/encoder_dual_valve/encoder_objects.hpp"

namespace canfleet::devices::encoder {
namespace {

constexpr std::array<InputDefaults, 3> kFrequency{{
    {2, 40, 50, 5000, 5250, 50},
    {1, 80, 100, 10000, 10500, 100},
    {0, 80, 100, 10000, 10500, 100},
}};
constexpr InputDefaults kPwm{1, 10, 50, 950, 990, 1};
constexpr InputDefaults kDigital{0, 0, 0, 1, 1, 0};
constexpr std::array<InputDefaults, 3> kQuadrature{{
    {0, -32768, 0, 10000, 32767, 100},
    {0, 0, 0, 1, 1, 0},
    {0, 0, 0, 3000, 32767, 100},
}};

}  // namespace

std::uint8_t MaxRange(std::uint16_t sensor_type, std::uint8_t mode) {
  if (mode == static_cast<std::uint8_t>(OperatingMode::kDigital) &&
      sensor_type != static_cast<std::uint16_t>(SensorType::kQuadrature))
    return 2;
  return sensor_type == static_cast<std::uint16_t>(SensorType::kPwm) ? 1 : 2;
}

std::optional<InputDefaults> InputDefaultsFor(std::uint16_t sensor_type, std::uint8_t mode,
                                              std::uint8_t range) {
  if (mode == static_cast<std::uint8_t>(OperatingMode::kOff)) return std::nullopt;
  if (range > MaxRange(sensor_type, mode)) return std::nullopt;
  switch (static_cast<SensorType>(sensor_type)) {
    case SensorType::kQuadrature:
      return kQuadrature[range];
    case SensorType::kFrequency:
      if (mode == static_cast<std::uint8_t>(OperatingMode::kDigital)) return kDigital;
      return kFrequency[range];
    case SensorType::kPwm:
      if (mode == static_cast<std::uint8_t>(OperatingMode::kDigital)) return kDigital;
      return kPwm;
  }
  return std::nullopt;
}

}  // namespace canfleet::devices::encoder
