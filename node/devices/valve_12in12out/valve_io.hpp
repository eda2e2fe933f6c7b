#pragma once
/// @file The valve controller's simulated I/O (UMAX020411A §1.1, §2.1, §4 "Input/Output
/// Specifications"): what a test can put on the pins and what it can measure on the outputs.
///
/// Inputs (defaults inside every default range: an idle node at factory defaults raises no fault):
///   UIn.voltage_mV     n = 1..7   0..36000, 2500   voltage at UIn (6110h = 40). The manual's
///                                 defaults (span start 200 mV, 2110h TRUE) would make an open input
///                                 at 0 V raise 40nnF001h after 1 s: the pins default mid-range.
///   UIn.current_uA     n = 1..7   0..30000, 12000  current into UIn (6110h = 50; FV in mA)
///   UIn.resistance_ohm n = 1..6   0..300000, 10000 resistance at UIn (6110h = 11000)
///   UIn.frequency_Hz   n = 1,3,5,7  0..50000, 1000 frequency at UIn (6110h = 60; RPM with 2101h)
///   UIn.duty_pct       n = 1,3,5,7  0..100, 50     PWM duty cycle at UIn (6110h = 10000)
///   UIn.level          n = 1..7   open|high|low   the pin read as a digital input (6112h = 10)
///   DIn.level          n = 1..5   open|high|low   DI1-DI5 as digital inputs (default mode)
///   DIn.frequency_Hz, DIn.duty_pct  n = 1,3,5     DI1/3/5 as frequency / PWM inputs
///   VPS.voltage_V      0..70, 24                  supply voltage (5020h)
///   TEMP.temperature_C -50..150, 40               processor temperature (5030h)
///   OUTn.load          n = 1..8   nominal|open|short  the load on OUTn
///   OUTn.load_current_mA n = 1..8 0..3000, 1000  what the load draws when OUTn is switched on as an
///                                 on/off digital output (6310h = 1000)
///   DOn.load           n = 1..4   nominal|open|short
///   DOn.load_current_mA n = 1..4  0..3000, 1000
/// Outputs:
///   OUTn.on            the driver is on (not shut off by short-circuit protection)
///   OUTn.current_mA    current through the load (current, hotshot and digital types)
///   OUTn.voltage_mV    average voltage at the pin (voltage type: the FV up to the supply; PWM and
///                      digital: duty x supply)
///   OUTn.duty_pct      PWM duty cycle of the driver (PWM type: the FV; voltage: FV / supply)
///   OUTn.dither_mA, OUTn.dither_Hz  dither on a current output (2320h/2321h; 0 when none)
///   DOn.on, DOn.current_mA

#include <array>

#include "node/devices/simulated_io.hpp"
#include "node/devices/valve_12in12out/valve_objects.hpp"

namespace canfleet::devices::valve {

inline constexpr const char* kLoadNominal = "nominal";
inline constexpr const char* kLoadOpen = "open";
inline constexpr const char* kLoadShort = "short";
inline constexpr const char* kLevelOpen = "open";
inline constexpr const char* kLevelHigh = "high";
inline constexpr const char* kLevelLow = "low";

/// Which measurements a pin supports (§1.1): resistance on UI1-6; frequency, PWM and counter on
/// UI1, 3, 5, 7 and DI1, 3, 5; voltage and current on UI1-7; DI2 and DI4 are digital only.
bool HasVoltage(int input);
bool HasResistance(int input);
bool HasPulse(int input);

struct ValveIo {
  /// Declares every signal on `io`.
  explicit ValveIo(SimulatedIo& io);

  SimulatedIo& io;
  // Inputs, indexed by input channel 0..11 (null where the pin lacks the quantity).
  std::array<IoSignal*, kInputs> voltage{};
  std::array<IoSignal*, kInputs> current{};
  std::array<IoSignal*, kInputs> resistance{};
  std::array<IoSignal*, kInputs> frequency{};
  std::array<IoSignal*, kInputs> duty{};
  std::array<IoSignal*, kInputs> level{};
  IoSignal* supply = nullptr;
  IoSignal* temperature = nullptr;
  // Outputs, indexed by output channel 0..11 (OUT1-8, DO1-4).
  std::array<IoSignal*, kOutputs> load{};
  std::array<IoSignal*, kOutputs> load_current{};
  std::array<IoSignal*, kOutputs> on{};
  std::array<IoSignal*, kOutputs> current_out{};
  std::array<IoSignal*, kOutputs> voltage_out{};  ///< OUT1-8 only
  std::array<IoSignal*, kOutputs> duty_out{};     ///< OUT1-8 only
  std::array<IoSignal*, kOutputs> dither_amplitude{};
  std::array<IoSignal*, kOutputs> dither_frequency{};
};

/// The catalog's signal declaration: declares the valve's signals into an empty SimulatedIo.
void DeclareValveSignals(SimulatedIo& io);

}  // namespace canfleet::devices::valve
