#pragma once
/// @file The Quad's simulated I/O (AX020506 §1.1, §1.2, Appendix A): what a test can put on the
/// pins and what it can measure on the outputs.
///
/// Inputs (defaults in the normal range: an idle node raises no faults):
///   AINn.voltage_mV   0..36000, 2500   voltage on AINn (read when 6110h.n = 40 or 42)
///   AINn.current_uA   0..40000, 12000  current into AINn (read when 6110h.n = 51 or 52)
///   FINn.duty_pct     0..100, 50       duty cycle on FINn (6110h = 10000, PWM)
///   FINn.frequency_Hz 0..50000, 1000   frequency on FINn (6110h = 60)
///   DINn.level        open|high|low    the pin as a digital input (6112h = 10); DIN1-4 = AIN1-4,
///                                      DIN5-6 = FIN1-2; open = floating, 2000h's pull decides
///   POUTn.load        nominal|open|short  the load on POUTn
///   POUTn.load_current_mA 0..2000, 1000 what the load draws when POUTn is switched on as a
///                                      digital output (6310h = 1000)
///   DOUT.load         nominal|open|short
/// Outputs:
///   POUTn.current_mA  the current through the load (= 30C0h)
///   POUTn.on          the driver is on (and not shut off by its short-circuit protection)
///   POUTn.dither_mA, POUTn.dither_Hz  dither superimposed on the current (0 when none)
///   DOUT.on           the DOUT driver is on

#include <array>

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

}  // namespace canfleet::devices::quad
