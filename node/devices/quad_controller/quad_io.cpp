#include "node/devices/quad_controller/quad_io.hpp"

#include <string>

namespace canfleet::devices::quad {

QuadIo::QuadIo(SimulatedIo& sim) : io(sim) {
  const std::vector<std::string> loads = {kLoadNominal, kLoadOpen, kLoadShort};
  const std::vector<std::string> levels = {kLevelOpen, kLevelHigh, kLevelLow};
  for (int i = 0; i < kAnalogInputs; ++i) {
    const std::string ch = "AIN" + std::to_string(i + 1);
    // 0..36 V: the inputs tolerate the whole supply range (Appendix A).
    ain_voltage[i] = &io.AddInput(NumberSpec(ch + ".voltage_mV", "mV", 0, 36000, 2500, "voltage at " + ch));
    // 10 V continuous across the 249 ohm sense resistor: about 40 mA.
    ain_current[i] =
        &io.AddInput(NumberSpec(ch + ".current_uA", "uA", 0, 40000, 12000, "current into " + ch));
  }
  for (int i = 0; i < kInputs - kAnalogInputs; ++i) {
    const std::string ch = "FIN" + std::to_string(i + 1);
    fin_duty[i] = &io.AddInput(NumberSpec(ch + ".duty_pct", "%", 0, 100, 50, "PWM duty cycle at " + ch));
    fin_frequency[i] =
        &io.AddInput(NumberSpec(ch + ".frequency_Hz", "Hz", 0, 50000, 1000, "signal frequency at " + ch));
  }
  for (int i = 0; i < kInputs; ++i) {
    const std::string ch = "DIN" + std::to_string(i + 1);
    din_level[i] =
        &io.AddInput(EnumSpec(ch + ".level", levels, kLevelOpen, ch + " pin: floating, driven high or low"));
  }
  for (int i = 0; i < kPouts; ++i) {
    const std::string ch = "POUT" + std::to_string(i + 1);
    pout_load[i] = &io.AddInput(EnumSpec(ch + ".load", loads, kLoadNominal, "load on " + ch));
    pout_load_current[i] = &io.AddInput(NumberSpec(ch + ".load_current_mA", "mA", 0, 2000, 1000,
                                                   "current the load draws when " + ch + " is on"));
  }
  dout_load = &io.AddInput(EnumSpec("DOUT.load", loads, kLoadNominal, "load on DOUT"));

  for (int i = 0; i < kPouts; ++i) {
    const std::string ch = "POUT" + std::to_string(i + 1);
    pout_current[i] =
        &io.AddOutput(NumberSpec(ch + ".current_mA", "mA", 0, 0, 0, "current through the load"));
    pout_on[i] = &io.AddOutput(BoolSpec(ch + ".on", false, ch + " driver on"));
    pout_dither_amplitude[i] =
        &io.AddOutput(NumberSpec(ch + ".dither_mA", "mA", 0, 0, 0, "dither amplitude"));
    pout_dither_frequency[i] =
        &io.AddOutput(NumberSpec(ch + ".dither_Hz", "Hz", 0, 0, 0, "dither frequency"));
  }
  dout_on = &io.AddOutput(BoolSpec("DOUT.on", false, "DOUT driver on"));
}

}  // namespace canfleet::devices::quad
