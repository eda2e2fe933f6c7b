#include "node/devices/valve_12in12out/valve_io.hpp"

#include <string>
#include <vector>

namespace canfleet::devices::valve {

bool HasVoltage(int input) {
  return input < kUniversalInputs;
}
bool HasResistance(int input) {
  return input < 6;
}
bool HasPulse(int input) {
  // UI1, UI3, UI5, UI7 (ch 0, 2, 4, 6) and DI1, DI3, DI5 (ch 7, 9, 11).
  return input < kUniversalInputs ? input % 2 == 0 : (input - kUniversalInputs) % 2 == 0;
}

namespace {

// IN1-IN12 and OUT1-OUT12 as the sub-indices of every 12-entry I/O object number them (§2.1):
// IN1-7 are the manual's UI1-7, IN8-12 its DI1-5; OUT1-8 its OUT1-8, OUT9-12 its DO1-4.
std::string InputName(int ch) {
  return "IN" + std::to_string(ch + 1);
}

std::string OutputName(int ch) {
  return "OUT" + std::to_string(ch + 1);
}

std::string ManualInputName(int ch) {
  return ch < kUniversalInputs ? "UI" + std::to_string(ch + 1)
                               : "DI" + std::to_string(ch - kUniversalInputs + 1);
}

std::string ManualOutputName(int ch) {
  return ch < kProportionalOutputs ? "OUT" + std::to_string(ch + 1)
                                   : "DO" + std::to_string(ch - kProportionalOutputs + 1);
}

}  // namespace

ValveIo::ValveIo(SimulatedIo& sim) : io(sim) {
  const std::vector<std::string> loads = {kLoadNominal, kLoadOpen, kLoadShort};
  const std::vector<std::string> levels = {kLevelOpen, kLevelHigh, kLevelLow};
  for (int ch = 0; ch < kInputs; ++ch) {
    const std::string name = InputName(ch);
    const std::string pin = name + " (" + ManualInputName(ch) + ")";
    if (HasVoltage(ch)) {
      // 0..36 V: the absolute maximum of a voltage input (§4 Table 1.0). 2500 mV sits inside the
      // default span of both voltage ranges (200..4800 / 200..9800 mV, Table 10).
      voltage[ch] = &io.AddInput(NumberSpec(name + ".voltage_mV", "mV", 0, 36000, 2500, "voltage at " + pin));
      current[ch] = &io.AddInput(NumberSpec(name + ".current_mA", "mA", 0, 30, 12, "current into " + pin));
    }
    if (HasResistance(ch))
      resistance[ch] =
          &io.AddInput(NumberSpec(name + ".resistance_ohm", "ohm", 0, 300000, 10000, "resistance at " + pin));
    if (HasPulse(ch)) {
      frequency[ch] = &io.AddInput(
          NumberSpec(name + ".frequency_Hz", "Hz", 0, 50000, 1000, "signal frequency at " + pin));
      duty[ch] = &io.AddInput(NumberSpec(name + ".duty_pct", "pct", 0, 100, 50, "PWM duty cycle at " + pin));
    }
    level[ch] = &io.AddInput(EnumSpec(name + ".level", levels, kLevelOpen, pin + ": floating, high or low"));
  }
  supply = &io.AddInput(NumberSpec("VPS.voltage_mV", "mV", 0, 70000, 24000, "supply voltage"));
  temperature = &io.AddInput(NumberSpec("TEMP.temperature_C", "C", -50, 150, 40, "processor temperature"));
  for (int ch = 0; ch < kOutputs; ++ch) {
    const std::string name = OutputName(ch);
    load[ch] = &io.AddInput(
        EnumSpec(name + ".load", loads, kLoadNominal, "load on " + name + " (" + ManualOutputName(ch) + ")"));
    load_current[ch] = &io.AddInput(NumberSpec(name + ".load_current_mA", "mA", 0, 3000, 1000,
                                               "current the load draws when " + name + " is switched on"));
  }
  for (int ch = 0; ch < kOutputs; ++ch) {
    const std::string name = OutputName(ch);
    on[ch] = &io.AddOutput(BoolSpec(name + ".on", false, name + " driver on"));
    current_out[ch] =
        &io.AddOutput(NumberSpec(name + ".current_mA", "mA", 0, 0, 0, "current through the load"));
    if (ch < kProportionalOutputs) {
      voltage_out[ch] =
          &io.AddOutput(NumberSpec(name + ".voltage_mV", "mV", 0, 0, 0, "average voltage at the pin"));
      duty_out[ch] = &io.AddOutput(NumberSpec(name + ".duty_pct", "pct", 0, 0, 0, "driver duty cycle"));
      dither_amplitude[ch] =
          &io.AddOutput(NumberSpec(name + ".dither_mA", "mA", 0, 0, 0, "dither amplitude"));
      dither_frequency[ch] =
          &io.AddOutput(NumberSpec(name + ".dither_Hz", "Hz", 0, 0, 0, "dither frequency"));
    }
  }
  io.SetAliasTable(&ValveSignalAliases);
}

std::vector<IoAlias> ValveSignalAliases() {
  std::vector<IoAlias> aliases;
  for (int ch = 0; ch < kInputs; ++ch) {
    const std::string old = ManualInputName(ch);
    const std::string now = InputName(ch);
    aliases.push_back({old + ".level", now + ".level"});
    if (HasVoltage(ch)) {
      aliases.push_back({old + ".voltage_mV", now + ".voltage_mV"});
      aliases.push_back({old + ".current_uA", now + ".current_mA", 1000.0});
    }
    if (HasResistance(ch)) aliases.push_back({old + ".resistance_ohm", now + ".resistance_ohm"});
    if (HasPulse(ch)) {
      aliases.push_back({old + ".frequency_Hz", now + ".frequency_Hz"});
      aliases.push_back({old + ".duty_pct", now + ".duty_pct"});
    }
  }
  for (int ch = kProportionalOutputs; ch < kOutputs; ++ch) {  // DOn; OUT1-8 keep their names
    for (const char* q : {".load", ".load_current_mA", ".on", ".current_mA"})
      aliases.push_back({ManualOutputName(ch) + q, OutputName(ch) + q});
  }
  aliases.push_back({"VPS.voltage_V", "VPS.voltage_mV", 0.001});
  return aliases;
}

void DeclareValveSignals(SimulatedIo& io) {
  ValveIo declared(io);
}

}  // namespace canfleet::devices::valve
