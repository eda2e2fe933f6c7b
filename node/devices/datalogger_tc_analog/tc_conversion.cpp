#include "node/devices/datalogger_tc_analog/tc_conversion.hpp"

#include <algorithm>
#include <array>

namespace canfleet::devices::datalogger {

using thermocouple::ThermocoupleType;

std::optional<ThermocoupleType> TcTypeFromCode(std::uint16_t code) {
  static constexpr std::array<ThermocoupleType, 8> kTypes = {
      ThermocoupleType::kJ, ThermocoupleType::kK, ThermocoupleType::kN, ThermocoupleType::kR,
      ThermocoupleType::kS, ThermocoupleType::kT, ThermocoupleType::kB, ThermocoupleType::kE};
  if (code < 1 || code > kTypes.size()) return std::nullopt;
  return kTypes[code - 1u];
}

double EmfClamped(ThermocoupleType type, double celsius) {
  const thermocouple::Range range = thermocouple::TemperatureRange(type);
  return thermocouple::EmfFromTemperature(type, std::clamp(celsius, range.min, range.max)).value_or(0.0);
}

double TemperatureFromEmfWide(ThermocoupleType type, double millivolts) {
  if (auto t = thermocouple::TemperatureFromEmf(type, millivolts)) return *t;
  thermocouple::Range range = thermocouple::TemperatureRange(type);
  // Type B's EMF falls from 0 C to a minimum near 21 C and rises after: search the rising part.
  if (type == ThermocoupleType::kB) range.min = 21.0;
  double lo = range.min;
  double hi = range.max;
  if (millivolts <= EmfClamped(type, lo)) return type == ThermocoupleType::kB ? 0.0 : lo;
  if (millivolts >= EmfClamped(type, hi)) return hi;
  // 60 halvings of at most ~2100 C: far below the 0.1 C resolution of 6100h.
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (EmfClamped(type, mid) < millivolts ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

TcReading ConvertThermocouple(ThermocoupleType type, double hot_c, double cold_c, bool compensate) {
  TcReading r;
  r.cold_junction_mv = EmfClamped(type, cold_c);
  r.measured_mv = EmfClamped(type, hot_c) - r.cold_junction_mv;
  r.temperature_c =
      TemperatureFromEmfWide(type, compensate ? r.measured_mv + r.cold_junction_mv : r.measured_mv);
  return r;
}

}  // namespace canfleet::devices::datalogger
