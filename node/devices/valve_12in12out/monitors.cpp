#include "node/devices/valve_12in12out/monitors.hpp"

#include "node/devices/family/family_error_policy.hpp"

namespace canfleet::devices::valve {

Monitors::Monitors(canopen::CanopenStack& stack, Scheduler& scheduler, const ValveIo& io)
    : io_(io),
      voltage_(stack.od(), kSupplyVoltage, 0),
      supply_enable_(stack.od(), kSupplyEnable, 0),
      under_(stack.od(), kSupplyUnder, 0),
      over_(stack.od(), kSupplyOver, 0),
      supply_hysteresis_(stack.od(), kSupplyHysteresis, 0),
      temperature_(stack.od(), kTemperature, 0),
      temperature_enable_(stack.od(), kTemperatureEnable, 0),
      temperature_over_(stack.od(), kTemperatureOver, 0),
      temperature_hysteresis_(stack.od(), kTemperatureHysteresis, 0),
      under_fault_(scheduler, stack, family::MakeFamilyEntry(kEmcyVoltage, kDescNegativeOverload, 0), 0),
      over_fault_(scheduler, stack, family::MakeFamilyEntry(kEmcyVoltage, kDescPositiveOverload, 0), 0),
      temperature_fault_(scheduler, stack,
                         family::MakeFamilyEntry(kEmcyTemperature, kDescPositiveOverload, 0), 0) {}

void Monitors::Run() {
  const double volts = io_.supply->Number() / 1000.0;  // 5020h counts V
  const double celsius = io_.temperature->Number();
  voltage_.SetNumber(volts);
  temperature_.SetNumber(celsius);

  const auto under = static_cast<double>(under_.Get());
  const auto over = static_cast<double>(over_.Get());
  const auto hysteresis = static_cast<double>(supply_hysteresis_.Get());
  if (supply_enable_.Get() == 0) {
    under_active_ = over_active_ = false;
  } else {
    if (volts < under)
      under_active_ = true;
    else if (volts >= under + hysteresis)
      under_active_ = false;
    if (volts > over)
      over_active_ = true;
    else if (volts <= over - hysteresis)
      over_active_ = false;
  }
  const auto limit = static_cast<double>(temperature_over_.Get());
  if (temperature_enable_.Get() == 0) {
    hot_active_ = false;
  } else if (celsius > limit) {
    hot_active_ = true;
  } else if (celsius <= limit - static_cast<double>(temperature_hysteresis_.Get())) {
    hot_active_ = false;
  }
  under_fault_.Update(under_active_, Duration::zero());
  over_fault_.Update(over_active_, Duration::zero());
  temperature_fault_.Update(hot_active_, Duration::zero());
}

void Monitors::Reset() {
  under_active_ = over_active_ = hot_active_ = false;
  under_fault_.Reset();
  over_fault_.Reset();
  temperature_fault_.Reset();
}

}  // namespace canfleet::devices::valve
