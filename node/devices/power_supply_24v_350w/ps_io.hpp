#pragma once
/// @file The power supply's simulated I/O (UMAX080311 §1.4 pinout, §3 specifications): what a test
/// puts on the connector and what it measures on the output.
///
/// Inputs (defaults in the normal range: an idle node raises no fault):
///   VIN.voltage_V          0..60, 24      supply on Input+ / Input- (pins 4-6 / 7-9); §3: 10-40 V
///                                         range, hardware shutdown below 8.5 V and above 44 V
///   ENABLE.level           low|high, low  the isolated Enable input (pins 3/10); high = 5-24 V
///   LOAD.mode              resistance|current, resistance  which of the two load inputs applies
///   LOAD.resistance_ohm    0..1e6, 24     a resistive load (0 = short circuit); 24 ohm draws 1 A
///   LOAD.current_A         0..40, 1       a current demand (an electronic load)
///   TEMP.temperature_C     -55..150, 25   the unit's temperature (6020h); §3 operating -40..85 degC
/// Outputs:
///   PS.output_on           the power stage delivers (firmware enable and no hardware shutdown)
///   VOUT.voltage_V         voltage on Output+ / Output- (pins 1/12)
///   IOUT.current_A         current into the load
///   IIN.current_A          current drawn from the input (94 % efficiency, §3)
///   PS.current_limit_A     the current limit in force (Fig. 2 or 6205h.8, see power_model.hpp)
///   PS.current_limited     the load asks for more than the limit: constant-current operation
///   PS.state               off|on|shutdown_delay|fault|fault_latched|protection (output_control.hpp)
///   PS.protection          none|undervoltage|overvoltage: the hardware input protection (§3)
///   PS.commanded_on        the output command after source selection and deglitch (§1.2.1)
///   PS.asleep              the controller sleeps (§1.2.2): it sends nothing until woken

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
};

}  // namespace canfleet::devices::ps
