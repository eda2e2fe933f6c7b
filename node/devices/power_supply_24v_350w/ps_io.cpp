#include "node/devices/power_supply_24v_350w/ps_io.hpp"

#include <string>
#include <vector>

#include "node/devices/power_supply_24v_350w/output_control.hpp"

namespace canfleet::devices::ps {

PsIo::PsIo(SimulatedIo& sim) : io(sim) {
  vin = &io.AddInput(
      NumberSpec("VIN.voltage_mV", "mV", 0, 60000, 24000, "input supply voltage (24 V nominal, 10-40 V)"));
  enable = &io.AddInput(EnumSpec("ENABLE.level", {kLevelLow, kLevelHigh}, kLevelLow,
                                 "Enable input: high (5-24 V) switches the output on"));
  load_mode = &io.AddInput(EnumSpec("LOAD.mode", {kLoadResistance, kLoadCurrent}, kLoadResistance,
                                    "which load input applies: LOAD.resistance_ohm or LOAD.current_mA"));
  load_resistance = &io.AddInput(NumberSpec("LOAD.resistance_ohm", "ohm", 0, 1e6, 24,
                                            "resistive load on the output (0 = short circuit)"));
  load_current = &io.AddInput(
      NumberSpec("LOAD.current_mA", "mA", 0, 40000, 1000, "current the load demands (electronic load)"));
  temperature =
      &io.AddInput(NumberSpec("TEMP.temperature_C", "C", -55, 150, 25, "temperature of the unit (6020h)"));

  output_on = &io.AddOutput(BoolSpec("PS.output_on", false, "the output delivers power"));
  vout = &io.AddOutput(NumberSpec("VOUT.voltage_mV", "mV", 0, 0, 0.0, "output voltage"));
  iout = &io.AddOutput(NumberSpec("IOUT.current_mA", "mA", 0, 0, 0.0, "output current"));
  iin = &io.AddOutput(NumberSpec("IIN.current_mA", "mA", 0, 0, 0.0, "input current (94 % efficiency)"));
  current_limit = &io.AddOutput(NumberSpec("PS.current_limit_mA", "mA", 0, 0, 0.0, "current limit in force"));
  current_limited =
      &io.AddOutput(BoolSpec("PS.current_limited", false, "the output runs at its current limit"));
  std::vector<std::string> states;
  for (OutputState s : kOutputStates)
    states.emplace_back(StateName(s));
  state = &io.AddOutput(EnumSpec("PS.state", std::move(states), std::string(StateName(OutputState::kOff)),
                                 "output state machine (manual 1.2.1, 1.2.3)"));
  protection = &io.AddOutput(EnumSpec("PS.protection", {kProtectionNone, kProtectionUnder, kProtectionOver},
                                      kProtectionNone, "hardware input protection holding the output off"));
  commanded_on =
      &io.AddOutput(BoolSpec("PS.commanded_on", false, "the output command after source selection"));
  asleep = &io.AddOutput(BoolSpec("PS.asleep", false, "the controller sleeps (manual 1.2.2)"));
  io.SetAliasTable(&PsSignalAliases);
}

std::string PsIo::IgnoredInput(const IoSignal& input) const {
  if (&input == load_resistance && !load_mode->Is(kLoadResistance))
    return IgnoredNotice(input, "LOAD.mode = current", "LOAD.mode = resistance reads it");
  if (&input == load_current && !load_mode->Is(kLoadCurrent))
    return IgnoredNotice(input, "LOAD.mode = resistance", "LOAD.mode = current reads it");
  return {};
}

std::vector<IoAlias> PsSignalAliases() {
  // The channels were already named channels; volts and amperes became the objects' mV and mA.
  return {{"VIN.voltage_V", "VIN.voltage_mV", 0.001},   {"LOAD.current_A", "LOAD.current_mA", 0.001},
          {"VOUT.voltage_V", "VOUT.voltage_mV", 0.001}, {"IOUT.current_A", "IOUT.current_mA", 0.001},
          {"IIN.current_A", "IIN.current_mA", 0.001},   {"PS.current_limit_A", "PS.current_limit_mA", 0.001}};
}

}  // namespace canfleet::devices::ps
