#pragma once
/// @file The power supply's simulated I/O (UMAX080311 §1.4 pinout, §3 specifications): what a test
/// puts on the connector and what it measures on the output.
///
/// Names and units: node/devices/README.md "Signals" (named channels: the product has no numbered
/// pins; mV and mA as 6113h/6204h count). The old V and A names: PsSignalAliases.
///
/// Inputs (defaults in the normal range: an idle node raises no fault):
///   VIN.voltage_mV         0..60000, 24000  supply on Input+ / Input- (pins 4-6 / 7-9); §3: 10-40 V
///                                         range, hardware shutdown below 8.5 V and above 44 V
///   ENABLE.level           low|high, low  the isolated Enable input (pins 3/10); high = 5-24 V
///   LOAD.mode              resistance|current, resistance  which of the two load inputs applies
///   LOAD.resistance_ohm    0..1e6, 24     a resistive load (0 = short circuit); 24 ohm draws 1 A
///   LOAD.current_mA        0..40000, 1000 a current demand (an electronic load)
///   TEMP.temperature_C     -55..150, 25   the unit's temperature (6020h); §3 operating -40..85 degC
/// Outputs:
///   PS.output_on           the power stage delivers (firmware enable and no hardware shutdown)
///   VOUT.voltage_mV        voltage on Output+ / Output- (pins 1/12)
///   IOUT.current_mA        current into the load
///   IIN.current_mA         current drawn from the input (94 % efficiency, §3)
///   PS.current_limit_mA    the current limit in force (Fig. 2 or 6205h.8, see power_model.hpp)
///   PS.current_limited     the load asks for more than the limit: constant-current operation
///   PS.state               off|on|shutdown_delay|fault|fault_latched|protection (output_control.hpp)
///   PS.protection          none|undervoltage|overvoltage: the hardware input protection (§3)
///   PS.commanded_on        the output command after source selection and deglitch (§1.2.1)
///   PS.asleep              the controller sleeps (§1.2.2): it sends nothing until woken

#include <string>
#include <vector>

#include "node/devices/simulated_io.hpp"

namespace canfleet::devices::ps {

inline constexpr const char* kLevelLow = "low";
inline constexpr const char* kLevelHigh = "high";
inline constexpr const char* kLoadResistance = "resistance";
inline constexpr const char* kLoadCurrent = "current";
inline constexpr const char* kProtectionNone = "none";
inline constexpr const char* kProtectionUnder = "undervoltage";
inline constexpr const char* kProtectionOver = "overvoltage";

struct PsIo {
  /// Declares every signal on `io`.
  explicit PsIo(SimulatedIo& io);

  SimulatedIo& io;
  IoSignal* vin = nullptr;
  IoSignal* enable = nullptr;
  IoSignal* load_mode = nullptr;
  IoSignal* load_resistance = nullptr;
  IoSignal* load_current = nullptr;
  IoSignal* temperature = nullptr;

  IoSignal* output_on = nullptr;
  IoSignal* vout = nullptr;
  IoSignal* iout = nullptr;
  IoSignal* iin = nullptr;
  IoSignal* current_limit = nullptr;
  IoSignal* current_limited = nullptr;
  IoSignal* state = nullptr;
  IoSignal* protection = nullptr;
  IoSignal* commanded_on = nullptr;
  IoSignal* asleep = nullptr;

  /// The simulated I/O's ignored hook: the load input LOAD.mode does not apply.
  std::string IgnoredInput(const IoSignal& input) const;
};

/// The old names of the power supply's signals and their new ones; the one table, registered by PsIo.
std::vector<IoAlias> PsSignalAliases();

}  // namespace canfleet::devices::ps
