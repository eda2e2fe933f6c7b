#include "node/devices/datalogger_tc_analog/diagnostics_block.hpp"

#include <cmath>

#include "node/devices/family/family_error_policy.hpp"

namespace canfleet::devices::datalogger {

DiagnosticsBlock::DiagnosticsBlock(canopen::ObjectDictionary& od, const DataLoggerIo& io,
                                   Scheduler& scheduler, std::span<canopen::CanopenStack* const> stacks)
    : io_(io),
      supply_(od, kSupplyValue, 0),
      supply_enable_(od, kSupplyErrorEnable, 0),
      under_(od, kUnderVoltage, 0),
      over_(od, kOverVoltage, 0),
      supply_hysteresis_(od, kSupplyHysteresis, 0),
      temperature_(od, kCpuTemperature, 0),
      temperature_enable_(od, kCpuTemperatureEnable, 0),
      over_temperature_limit_(od, kOverTemperature, 0),
      temperature_hysteresis_(od, kCpuTemperatureHysteresis, 0),
      over_voltage_(std::make_unique<DeviceFault>(
          scheduler, stacks, family::MakeFamilyEntry(kEmcyVoltage, kDescPositiveOverload, 0), 0)),
      under_voltage_(std::make_unique<DeviceFault>(
          scheduler, stacks, family::MakeFamilyEntry(kEmcyVoltage, kDescNegativeOverload, 0), 0)),
      over_temperature_(std::make_unique<DeviceFault>(
          scheduler, stacks, family::MakeFamilyEntry(kEmcyDeviceTemperature, kDescPositiveOverload, 0), 0)) {}

void DiagnosticsBlock::Update() {
  const double volts = io_.supply->Number() / 1000.0;  // 5020h counts V
  const double celsius = io_.cpu_temperature->Number();
  supply_.SetNumber(volts);
  temperature_.SetNumber(celsius);

  if (supply_enable_.Get() != 0) {
    const auto hysteresis = static_cast<double>(supply_hysteresis_.Get());
    const auto over = static_cast<double>(over_.Get());
    const auto under = static_cast<double>(under_.Get());
    if (volts > over)
      over_voltage_flag_ = true;
    else if (over_voltage_flag_ && volts <= over - hysteresis)
      over_voltage_flag_ = false;
    if (volts < under)
      under_voltage_flag_ = true;
    else if (under_voltage_flag_ && volts >= under + hysteresis)
      under_voltage_flag_ = false;
  } else {
    over_voltage_flag_ = under_voltage_flag_ = false;
  }
  if (temperature_enable_.Get() != 0) {
    const auto limit = static_cast<double>(over_temperature_limit_.Get());
    if (celsius > limit)
      over_temperature_flag_ = true;
    else if (over_temperature_flag_ && celsius <= limit - static_cast<double>(temperature_hysteresis_.Get()))
      over_temperature_flag_ = false;
  } else {
    over_temperature_flag_ = false;
  }
  over_voltage_->Set(over_voltage_flag_);
  under_voltage_->Set(under_voltage_flag_);
  over_temperature_->Set(over_temperature_flag_);
}

blocks::Signal DiagnosticsBlock::SupplySource() const {
  blocks::Signal s = blocks::Signal::Constant(std::round(supply_.GetNumber() * 10.0));
  s.decimal_digits = 1;
  return s;
}

blocks::Signal DiagnosticsBlock::TemperatureSource() const {
  blocks::Signal s = blocks::Signal::Constant(std::round(temperature_.GetNumber() * 10.0));
  s.decimal_digits = 1;
  return s;
}

void DiagnosticsBlock::Reset() {
  over_voltage_flag_ = under_voltage_flag_ = over_temperature_flag_ = false;
}

void DiagnosticsBlock::ResetPort(std::size_t port) {
  over_voltage_->ResetPort(port);
  under_voltage_->ResetPort(port);
  over_temperature_->ResetPort(port);
}

}  // namespace canfleet::devices::datalogger
