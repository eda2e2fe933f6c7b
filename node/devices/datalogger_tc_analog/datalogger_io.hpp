#pragma once
/// @file The data logger's simulated I/O (UMAX181001 §1.1-§1.4, §4 technical specifications): what
/// a test can put on its pins. The product has no outputs; what it measures is read from its
/// objects (7100h, 6100h, 5020h ...) over either CAN port.
///
/// Inputs (defaults in the normal range, except that the TC limits trip at room temperature with
/// the factory thresholds, README "Factory thresholds"):
///   TCn.temperature_C   -270..1820, 25   hot (measuring) junction of thermocouple n (1-4)
///   TCn.open            false            thermocouple n broken / not connected (ADC over-range)
///   CJ.temperature_C    -40..125, 25     the cold-junction sensor next to the TC connectors
///   INn.voltage_mV      0..36000, 2500   voltage at input n (1-10), read when 6110h.n = 40
///   INn.current_mA      0..40, 12        current into input n, read when 6110h.n = 50
///   INn.frequency_Hz    0..50000, 1000   inputs 8 and 9 only: frequency / RPM (6110h = 60)
///   INn.duty_pct        0..100, 50       inputs 8 and 9 only: PWM duty cycle (6110h = 10000)
///   INn.level           open|high|low    inputs 8-10 as digital inputs (6112h = 10): open =
///                                        floating, 2020h's pull-up decides
///   VPS.voltage_mV      0..70000, 24000  supply voltage (5020h in V; 9-60 V nominal, §4)
/// Names: node/devices/README.md "Signals" (INn = the manual's Input n); the old AINn/DINn and
/// VPS.voltage_V: DataLoggerSignalAliases.
///   TEMP.temperature_C  -50..150, 35     processor temperature (5030h)

#include <array>
#include <vector>

#include "node/devices/datalogger_tc_analog/datalogger_objects.hpp"
#include "node/devices/simulated_io.hpp"

namespace canfleet::devices::datalogger {

/// Digital pin states.
inline constexpr const char* kLevelOpen = "open";
inline constexpr const char* kLevelHigh = "high";
inline constexpr const char* kLevelLow = "low";

/// Number of inputs that can measure frequency or PWM (8 and 9, §1.4 "only applicable for Input 8
/// and 9").
inline constexpr int kPulseInputs = 2;
inline constexpr int kFirstPulseInput = 8;

struct DataLoggerIo {
  /// Declares every signal on `io`.
  explicit DataLoggerIo(SimulatedIo& io);

  SimulatedIo& io;
  std::array<IoSignal*, kThermocouples> tc_temperature{};
  std::array<IoSignal*, kThermocouples> tc_open{};
  IoSignal* cold_junction = nullptr;
  std::array<IoSignal*, kAnalogInputs> ain_voltage{};
  std::array<IoSignal*, kAnalogInputs> ain_current{};
  /// Index i = input kFirstPulseInput + i.
  std::array<IoSignal*, kPulseInputs> ain_frequency{};
  std::array<IoSignal*, kPulseInputs> ain_duty{};
  /// Index i = input kFirstUniversal + i.
  std::array<IoSignal*, kAnalogInputs - kFirstUniversal + 1> din_level{};
  IoSignal* supply = nullptr;
  IoSignal* cpu_temperature = nullptr;
};

/// The old names of the data logger's signals (AINn, DINn, VPS.voltage_V) and their new ones; the
/// one table, registered by DataLoggerIo.
std::vector<IoAlias> DataLoggerSignalAliases();

/// The catalog's signal declaration (registry.hpp `declare_signals`).
void DeclareDataLoggerSignals(SimulatedIo& io);

}  // namespace canfleet::devices::datalogger
