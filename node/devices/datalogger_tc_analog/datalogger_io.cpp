#include "node/devices/datalogger_tc_analog/datalogger_io.hpp"

#include <string>
#include <vector>

namespace canfleet::devices::datalogger {

DataLoggerIo::DataLoggerIo(SimulatedIo& sim) : io(sim) {
  for (int i = 0; i < kThermocouples; ++i) {
    const std::string ch = "TC" + std::to_string(i + 1);
    // The widest table range of the eight types (IEC 60584-1: type K/E/T from -270 C, B to 1820 C).
    tc_temperature[i] = &io.AddInput(
        NumberSpec(ch + ".temperature_C", "C", -270, 1820, 25, "hot-junction temperature of " + ch));
    tc_open[i] = &io.AddInput(BoolSpec(ch + ".open", false, ch + " open circuit (broken or unplugged)"));
  }
  cold_junction = &io.AddInput(
      NumberSpec("CJ.temperature_C", "C", -40, 125, 25, "cold-junction sensor at the TC connectors"));
  const std::vector<std::string> levels = {kLevelOpen, kLevelHigh, kLevelLow};
  // IN1-IN10: the manual's Input 1-10 (AI1-7, universal 8-10), sub-indices 1-10 of 6110h/7100h.
  for (int i = 0; i < kAnalogInputs; ++i) {
    const int n = i + 1;
    const std::string ch = "IN" + std::to_string(n);
    // 0..36 V: a 24 V system's voltage on a voltage input; 40 mA: far past the 0-20 mA range.
    ain_voltage[i] = &io.AddInput(NumberSpec(ch + ".voltage_mV", "mV", 0, 36000, 2500, "voltage at " + ch));
    ain_current[i] = &io.AddInput(NumberSpec(ch + ".current_mA", "mA", 0, 40, 12, "current into " + ch));
    if (n >= kFirstPulseInput && n < kFirstPulseInput + kPulseInputs) {
      const std::size_t p = static_cast<std::size_t>(n - kFirstPulseInput);
      ain_frequency[p] =
          &io.AddInput(NumberSpec(ch + ".frequency_Hz", "Hz", 0, 50000, 1000, "signal frequency at " + ch));
      ain_duty[p] = &io.AddInput(NumberSpec(ch + ".duty_pct", "pct", 0, 100, 50, "PWM duty cycle at " + ch));
    }
  }
  for (int n = kFirstUniversal; n <= kAnalogInputs; ++n) {
    const std::string ch = "IN" + std::to_string(n);
    din_level[static_cast<std::size_t>(n - kFirstUniversal)] = &io.AddInput(EnumSpec(
        ch + ".level", levels, kLevelOpen, "input " + std::to_string(n) + " pin: floating, high or low"));
  }
  supply = &io.AddInput(NumberSpec("VPS.voltage_mV", "mV", 0, 70000, 24000, "supply voltage"));
  cpu_temperature =
      &io.AddInput(NumberSpec("TEMP.temperature_C", "C", -50, 150, 35, "processor temperature"));
  io.SetAliasTable(&DataLoggerSignalAliases);
}

std::vector<IoAlias> DataLoggerSignalAliases() {
  std::vector<IoAlias> aliases;
  for (int n = 1; n <= kAnalogInputs; ++n) {
    const std::string old = "AIN" + std::to_string(n);
    const std::string now = "IN" + std::to_string(n);
    aliases.push_back({old + ".voltage_mV", now + ".voltage_mV"});
    aliases.push_back({old + ".current_uA", now + ".current_mA", 1000.0});
    if (n >= kFirstPulseInput && n < kFirstPulseInput + kPulseInputs) {
      aliases.push_back({old + ".frequency_Hz", now + ".frequency_Hz"});
      aliases.push_back({old + ".duty_pct", now + ".duty_pct"});
    }
    if (n >= kFirstUniversal) aliases.push_back({"DIN" + std::to_string(n) + ".level", now + ".level"});
  }
  aliases.push_back({"VPS.voltage_V", "VPS.voltage_mV", 0.001});
  return aliases;
}

void DeclareDataLoggerSignals(SimulatedIo& io) {
  DataLoggerIo declared(io);
}

}  // namespace canfleet::devices::datalogger
