#include "node/devices/power_supply_24v_350w/power_model.hpp"

#include <algorithm>

namespace canfleet::devices::ps {
namespace {

constexpr double kMaxLimit_A = 15.0;            // Fig. 2 plateau, 6203h.3
constexpr double kPlateauFrom_V = 18.0;         // Fig. 2
constexpr double kSlope_A_per_V = 0.8455;       // Fig. 2 trend line
constexpr double kOffset_A = -0.2805;           // Fig. 2 trend line
constexpr double kNominalOutput_V = 24.0;       // §3 output voltage
constexpr double kFullRegulationFrom_V = 11.0;  // §3: ±2 % from 11 V input, 23-24 V at 10-11 V
constexpr double kEfficiency = 0.94;            // §3

}  // namespace

InputProtection::State InputProtection::Update(double vin_V) {
  switch (state_) {
    case State::kOk:
      if (vin_V < kUnderShutdown_V) state_ = State::kUnderVoltage;
      if (vin_V > kOverShutdown_V) state_ = State::kOverVoltage;
      break;
    case State::kUnderVoltage:
      if (vin_V > kOverShutdown_V)
        state_ = State::kOverVoltage;
      else if (vin_V >= kUnderRecover_V)
        state_ = State::kOk;
      break;
    case State::kOverVoltage:
      if (vin_V < kUnderShutdown_V)
        state_ = State::kUnderVoltage;
      else if (vin_V <= kOverRecover_V)
        state_ = State::kOk;
      break;
  }
  return state_;
}

void InputProtection::Reset(double vin_V) {
  state_ = State::kOk;
  Update(vin_V);
}

double ManufacturerCurrentLimit(double vin_V) {
  if (vin_V >= kPlateauFrom_V) return kMaxLimit_A;
  return std::clamp(kSlope_A_per_V * vin_V + kOffset_A, 0.0, kMaxLimit_A);
}

OutputPoint Operate(bool on, double set_voltage_V, double vin_V, double limit_A, const Load& load) {
  OutputPoint p;
  if (!on) return p;
  const double ceiling = kNominalOutput_V - std::max(0.0, kFullRegulationFrom_V - vin_V);
  const double regulated = std::clamp(set_voltage_V, 0.0, std::max(0.0, ceiling));
  const double limit = std::max(0.0, limit_A);
  if (load.is_resistance) {
    if (load.resistance_ohm <= 0.0) {
      p.voltage_V = 0.0;
      p.current_A = limit;
      p.current_limited = true;
    } else {
      const double demand = regulated / load.resistance_ohm;
      p.current_limited = demand > limit;
      p.current_A = std::min(demand, limit);
      p.voltage_V = p.current_limited ? p.current_A * load.resistance_ohm : regulated;
    }
  } else {
    const double demand = std::max(0.0, load.current_A);
    p.current_limited = demand > limit;
    p.current_A = std::min(demand, limit);
    p.voltage_V = p.current_limited ? regulated * limit / demand : regulated;
  }
  if (vin_V > 0.0) p.input_current_A = p.voltage_V * p.current_A / (kEfficiency * vin_V);
  return p;
}

}  // namespace canfleet::devices::ps
