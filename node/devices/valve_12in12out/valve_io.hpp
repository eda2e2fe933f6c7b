#pragma once
/// @file The valve controller's simulated I/O (UMAX020411A §1.1, §2.1, §4 "Input/Output
/// Specifications"): what a test can put on the pins and what it can measure on the outputs. Names
/// follow node/devices/README.md "Signals": IN1-IN12 and OUT1-OUT12 as the sub-indices of every
/// 12-entry I/O object number them (IN1-7 = the manual's UI1-7, IN8-12 = DI1-5; OUT9-12 = DO1-4).
///
/// Inputs (defaults inside every default range: an idle node at factory defaults raises no fault):
///   INn.voltage_mV     n = 1..7   0..36000, 2500   voltage at the pin (6110h = 40). The manual's
///                                 defaults (span start 200 mV, 2110h TRUE) would make an open input
///                                 at 0 V raise 40nnF001h after 1 s: the pins default mid-range.
///   INn.current_mA     n = 1..7   0..30, 12        current into the pin (6110h = 50; FV in mA)
///   INn.resistance_ohm n = 1..6   0..300000, 10000 resistance at the pin (6110h = 11000)
///   INn.frequency_Hz   n = 1,3,5,7,8,10,12  0..50000, 1000  frequency (6110h = 60; RPM with 2101h)
///   INn.duty_pct       n = 1,3,5,7,8,10,12  0..100, 50      PWM duty cycle (6110h = 10000)
///   INn.level          n = 1..12  open|high|low   the pin read as a digital input (6112h = 10;
///                                 the default of IN8-12)
///   VPS.voltage_mV     0..70000, 24000            supply voltage (5020h, in V)
///   TEMP.temperature_C -50..150, 40               processor temperature (5030h)
///   OUTn.load          n = 1..12  nominal|open|short  the load on the output
///   OUTn.load_current_mA n = 1..12 0..3000, 1000 what the load draws when OUTn is switched on as an
///                                 on/off digital output (6310h = 1000)
/// Outputs:
///   OUTn.on            n = 1..12  the driver is on (not shut off by short-circuit protection)
///   OUTn.current_mA    n = 1..12  current through the load (current, hotshot and digital types)
///   OUTn.voltage_mV    n = 1..8   average voltage at the pin (voltage type: the FV up to the supply;
///                                 PWM and digital: duty x supply)
///   OUTn.duty_pct      n = 1..8   PWM duty cycle of the driver (PWM type: the FV; voltage: FV / supply)
///   OUTn.dither_mA, OUTn.dither_Hz  n = 1..8  dither on a current output (2320h/2321h; 0 when none)
/// The old names (UIn, DIn, DOn, VPS.voltage_V): ValveSignalAliases.

#include <array>
#include <vector>

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

/// The old names of the valve's signals and their new ones; the one table, registered by ValveIo.
std::vector<IoAlias> ValveSignalAliases();

/// The catalog's signal declaration: declares the valve's signals into an empty SimulatedIo.
void DeclareValveSignals(SimulatedIo& io);

}  // namespace canfleet::devices::valve
