#pragma once
/// @file The Quad's simulated I/O (AX020506 §1.1, §1.2, Appendix A): what a test can put on the
/// pins and what it can measure on the outputs. Names follow node/devices/README.md "Signals":
/// IN1-IN6 are the manual's AIN1-4 and FIN1-2 (DIN1-6 as digital inputs), OUT1-OUT5 its POUT1-4
/// and DOUT, as the sub-indices of the per-channel objects number them.
///
/// Inputs (defaults in the normal range: an idle node raises no faults):
///   INn.voltage_mV      n = 1..4  0..36000, 2500  voltage at the pin (read when 6110h.n = 40 or 42)
///   INn.current_mA      n = 1..4  0..40, 12       current into the pin (6110h.n = 51 or 52; 7100h in uA)
///   INn.duty_pct        n = 5, 6  0..100, 50      duty cycle (6110h = 10000, PWM)
///   INn.frequency_Hz    n = 5, 6  0..50000, 1000  frequency (6110h = 60)
///   INn.level           n = 1..6  open|high|low   the pin as a digital input (6112h = 10); open =
///                                                 floating, 2000h's pull decides
///   OUTn.load           n = 1..5  nominal|open|short  the load on the output
///   OUTn.load_current_mA n = 1..4 0..2000, 1000  what the load draws when OUTn is switched on as a
///                                                 digital output (6310h = 1000)
/// Outputs:
///   OUTn.current_mA     n = 1..4  the current through the load (= 30C0h)
///   OUTn.on             n = 1..5  the driver is on (and not shut off by its short-circuit protection)
///   OUTn.dither_mA, OUTn.dither_Hz  n = 1..4  dither superimposed on the current (0 when none)
/// Setting a quantity the pin's configuration does not read is accepted with a notice
/// (QuadController's ignored hook). The old names (AIN1.voltage_mV, POUT1.current_mA ...):
/// QuadSignalAliases.

#include <array>
#include <vector>

#include "node/devices/quad_controller/quad_objects.hpp"
#include "node/devices/simulated_io.hpp"

namespace canfleet::devices::quad {

/// Load states of an output.
inline constexpr const char* kLoadNominal = "nominal";
inline constexpr const char* kLoadOpen = "open";
inline constexpr const char* kLoadShort = "short";
/// Digital pin states.
inline constexpr const char* kLevelOpen = "open";
inline constexpr const char* kLevelHigh = "high";
inline constexpr const char* kLevelLow = "low";

struct QuadIo {
  /// Declares every signal on `io`.
  explicit QuadIo(SimulatedIo& io);

  SimulatedIo& io;
  std::array<IoSignal*, kAnalogInputs> ain_voltage{};
  std::array<IoSignal*, kAnalogInputs> ain_current{};
  std::array<IoSignal*, kInputs - kAnalogInputs> fin_duty{};
  std::array<IoSignal*, kInputs - kAnalogInputs> fin_frequency{};
  std::array<IoSignal*, kInputs> din_level{};
  std::array<IoSignal*, kPouts> pout_load{};
  std::array<IoSignal*, kPouts> pout_load_current{};
  IoSignal* dout_load = nullptr;

  std::array<IoSignal*, kPouts> pout_current{};
  std::array<IoSignal*, kPouts> pout_on{};
  std::array<IoSignal*, kPouts> pout_dither_amplitude{};
  std::array<IoSignal*, kPouts> pout_dither_frequency{};
  IoSignal* dout_on = nullptr;
};

/// The old names of the Quad's signals (AINn, FINn, DINn, POUTn, DOUT) and their new ones; the one
/// table, registered by QuadIo.
std::vector<IoAlias> QuadSignalAliases();

}  // namespace canfleet::devices::quad
