#include "node/devices/quad_controller/quad_io.hpp"

#include <string>

namespace canfleet::devices::quad {

namespace {

std::string In(int n) {
  return "IN" + std::to_string(n);
}
std::string Out(int n) {
  return "OUT" + std::to_string(n);
}

}  // namespace

QuadIo::QuadIo(SimulatedIo& sim) : io(sim) {
  const std::vector<std::string> loads = {kLoadNominal, kLoadOpen, kLoadShort};
  const std::vector<std::string> levels = {kLevelOpen, kLevelHigh, kLevelLow};
  // IN1-IN4 are the manual's AIN1-4 (= DIN1-4), IN5-IN6 its FIN1-2 (= DIN5-6): sub-indices 1-6 of
  // every per-input object (§1.1, §3.3).
  for (int i = 0; i < kAnalogInputs; ++i) {
    const std::string ch = In(i + 1);
    const std::string manual = "AIN" + std::to_string(i + 1);
    // 0..36 V: the inputs tolerate the whole supply range (Appendix A).
    ain_voltage[i] = &io.AddInput(
        NumberSpec(ch + ".voltage_mV", "mV", 0, 36000, 2500, "voltage at " + ch + " (" + manual + ")"));
    // 10 V continuous across the 249 ohm sense resistor: about 40 mA. 7100h counts uA.
    ain_current[i] = &io.AddInput(
        NumberSpec(ch + ".current_mA", "mA", 0, 40, 12, "current into " + ch + " (" + manual + ")"));
  }
  for (int i = 0; i < kInputs - kAnalogInputs; ++i) {
    const std::string ch = In(kAnalogInputs + i + 1);
    const std::string manual = "FIN" + std::to_string(i + 1);
    fin_duty[i] = &io.AddInput(
        NumberSpec(ch + ".duty_pct", "pct", 0, 100, 50, "PWM duty cycle at " + ch + " (" + manual + ")"));
    fin_frequency[i] = &io.AddInput(NumberSpec(ch + ".frequency_Hz", "Hz", 0, 50000, 1000,
                                               "signal frequency at " + ch + " (" + manual + ")"));
  }
  for (int i = 0; i < kInputs; ++i) {
    const std::string ch = In(i + 1);
    din_level[i] =
        &io.AddInput(EnumSpec(ch + ".level", levels, kLevelOpen,
                              ch + " (DIN" + std::to_string(i + 1) + "): floating, driven high or low"));
  }
  // OUT1-OUT4 are POUT1-4, OUT5 is DOUT: sub-indices 1-5 (bits 0-4) of the output objects.
  for (int i = 0; i < kPouts; ++i) {
    const std::string ch = Out(i + 1);
    pout_load[i] = &io.AddInput(EnumSpec(ch + ".load", loads, kLoadNominal, "load on " + ch));
    pout_load_current[i] = &io.AddInput(NumberSpec(ch + ".load_current_mA", "mA", 0, 2000, 1000,
                                                   "current the load draws when " + ch + " is on"));
  }
  dout_load = &io.AddInput(EnumSpec(Out(kDout + 1) + ".load", loads, kLoadNominal, "load on OUT5 (DOUT)"));

  for (int i = 0; i < kPouts; ++i) {
    const std::string ch = Out(i + 1);
    pout_current[i] =
        &io.AddOutput(NumberSpec(ch + ".current_mA", "mA", 0, 0, 0, "current through the load"));
    pout_on[i] = &io.AddOutput(BoolSpec(ch + ".on", false, ch + " driver on"));
    pout_dither_amplitude[i] =
        &io.AddOutput(NumberSpec(ch + ".dither_mA", "mA", 0, 0, 0, "dither amplitude"));
    pout_dither_frequency[i] =
        &io.AddOutput(NumberSpec(ch + ".dither_Hz", "Hz", 0, 0, 0, "dither frequency"));
  }
  dout_on = &io.AddOutput(BoolSpec(Out(kDout + 1) + ".on", false, "OUT5 (DOUT) driver on"));

  io.SetAliasTable(&QuadSignalAliases);
}

std::vector<IoAlias> QuadSignalAliases() {
  std::vector<IoAlias> aliases;
  for (int n = 1; n <= kAnalogInputs; ++n) {
    const std::string old = "AIN" + std::to_string(n);
    aliases.push_back({old + ".voltage_mV", In(n) + ".voltage_mV"});
    aliases.push_back({old + ".current_uA", In(n) + ".current_mA", 1000.0});
  }
  for (int n = 1; n <= kInputs - kAnalogInputs; ++n) {
    const std::string old = "FIN" + std::to_string(n);
    aliases.push_back({old + ".duty_pct", In(kAnalogInputs + n) + ".duty_pct"});
    aliases.push_back({old + ".frequency_Hz", In(kAnalogInputs + n) + ".frequency_Hz"});
  }
  for (int n = 1; n <= kInputs; ++n)
    aliases.push_back({"DIN" + std::to_string(n) + ".level", In(n) + ".level"});
  for (int n = 1; n <= kPouts; ++n) {
    const std::string old = "POUT" + std::to_string(n);
    for (const char* quantity :
         {".load", ".load_current_mA", ".current_mA", ".on", ".dither_mA", ".dither_Hz"})
      aliases.push_back({old + quantity, Out(n) + quantity});
  }
  aliases.push_back({"DOUT.load", Out(kDout + 1) + ".load"});
  aliases.push_back({"DOUT.on", Out(kDout + 1) + ".on"});
  return aliases;
}

}  // namespace canfleet::devices::quad
