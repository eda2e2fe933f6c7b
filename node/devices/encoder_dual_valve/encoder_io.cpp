#include "node/devices/encoder_dual_valve/encoder_io.hpp"

#include <string>
#include <vector>

namespace canfleet::devices::encoder {

EncoderIo::EncoderIo(SimulatedIo& sim) : io(sim) {
  const std::vector<std::string> loads = {kLoadNominal, kLoadOpen, kLoadShort};
  const std::vector<std::string> levels = {kLevelOpen, kLevelHigh, kLevelLow};
  drive = &io.AddInput(
      EnumSpec("ENC.drive", {kDriveRpm, kDriveCounts, kDriveChannels}, kDriveRpm,
               "what turns the shaft: ENC.speed_rpm, ENC.speed_counts_s or the IN1/IN2 channels"));
  speed_rpm = &io.AddInput(NumberSpec("ENC.speed_rpm", "rpm", 0, 60000, 0, "shaft speed"));
  speed_counts = &io.AddInput(
      NumberSpec("ENC.speed_counts_s", "counts/s", 0, 2000000, 0, "shaft speed in quadrature edges/s"));
  direction = &io.AddInput(EnumSpec("ENC.direction", {kForward, kReverse}, kForward,
                                    "forward: QA leads QB, the counter counts up"));
  pulses_per_rev = &io.AddInput(NumberSpec("ENC.pulses_per_rev", "pulses/rev", 1, 100000, 4,
                                           "encoder pulses per revolution and channel"));
  position = &io.AddInput(NumberSpec("ENC.position_counts", "counts", -1e15, 1e15, 0,
                                     "moves the shaft to this position (edges from power-on)"));
  for (int i = 0; i < kInputs; ++i) {
    const std::string ch = "IN" + std::to_string(i + 1);
    level[i] =
        &io.AddInput(EnumSpec(ch + ".level", levels, kLevelOpen, ch + " pin: floating, driven high or low"));
    frequency[i] =
        &io.AddInput(NumberSpec(ch + ".frequency_Hz", "Hz", 0, 50000, 25, "signal frequency at " + ch));
    duty[i] = &io.AddInput(NumberSpec(ch + ".duty_pct", "pct", 0, 100, 50, "PWM duty cycle at " + ch));
  }
  for (int i = 0; i < kOutputs; ++i) {
    const std::string ch = "OUT" + std::to_string(i + 1);
    load[i] = &io.AddInput(EnumSpec(ch + ".load", loads, kLoadNominal, "load on " + ch));
    resistance[i] =
        &io.AddInput(NumberSpec(ch + ".resistance_ohm", "ohm", 0.5, 1000, 8, "coil resistance on " + ch));
  }
  supply = &io.AddInput(NumberSpec("VPS.voltage_mV", "mV", 0, 70000, 24000, "supply voltage (BATT+)"));
  temperature = &io.AddInput(NumberSpec("TEMP.temperature_C", "C", -55, 150, 25, "processor temperature"));

  shaft_counts =
      &io.AddOutput(NumberSpec("ENC.shaft_counts", "counts", 0, 0, 0, "shaft position since power-on"));
  for (int i = 0; i < kOutputs; ++i) {
    const std::string ch = "OUT" + std::to_string(i + 1);
    current[i] = &io.AddOutput(NumberSpec(ch + ".current_mA", "mA", 0, 0, 0, "current through the load"));
    voltage[i] = &io.AddOutput(NumberSpec(ch + ".voltage_mV", "mV", 0, 0, 0, "mean voltage across the load"));
    out_duty[i] = &io.AddOutput(NumberSpec(ch + ".duty_pct", "pct", 0, 0, 0, "driver duty cycle"));
    out_frequency[i] = &io.AddOutput(NumberSpec(ch + ".frequency_Hz", "Hz", 0, 0, 0, "driver frequency"));
    on[i] = &io.AddOutput(BoolSpec(ch + ".on", false, ch + " driver on"));
    hotshot[i] = &io.AddOutput(BoolSpec(ch + ".hotshot", false, ch + " in its hotshot phase"));
    tripped[i] = &io.AddOutput(BoolSpec(ch + ".tripped", false, ch + " off by its short-circuit protection"));
  }
  io.SetAliasTable(&EncoderSignalAliases);
}

std::vector<IoAlias> EncoderSignalAliases() {
  // IN1/IN2 and OUT1/OUT2 were already the manual's Input 1/2, Output 1/2; only units changed.
  return {{"VPS.voltage_V", "VPS.voltage_mV", 0.001},
          {"OUT1.voltage_V", "OUT1.voltage_mV", 0.001},
          {"OUT2.voltage_V", "OUT2.voltage_mV", 0.001}};
}

void DeclareEncoderSignals(SimulatedIo& io) {
  EncoderIo declared(io);
}

}  // namespace canfleet::devices::encoder
