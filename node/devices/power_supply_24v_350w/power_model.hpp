#pragma once
/// @file The physics of the PS-24-24-350W-CAN (UMAX080311 §1.2.1.3, §3): what the output delivers
/// for an input voltage, a load, a set voltage and a current limit. Everything here is plain
/// arithmetic on numbers; the device feeds it from its simulated inputs and objects.
///
/// - Hardware input protection (§3 "Undervoltage Protection: Shutdown at 8.5 VDC, Recovers at 11.5
///   VDC"; "Overvoltage Protection: Shutdown at 44 VDC, Recovers at 42 VDC"): analog, on the raw
///   input, independent of the firmware and of the CiA 453 thresholds.
/// - Current limit, 2330h = 0 (§1.2.1.3, Fig. 2): 15 A when the measured (filtered) input is at or
///   above 18 V, else I = 0.8455 V - 0.2805 (A, V), never below 0. 2330h = 1: 6205h.8 (mA), capped
///   by 6205h.9. Both are capped by 6203h.3 (15 A). The text and Fig. 2 agree on this curve; §3's
///   "18 A current limit (derated below 16 VDC)" is the hardware's short-circuit limit, which the
///   firmware limit (at most 15 A) never lets the output reach (README.md, choice 8).
/// - Regulation (§3 "24 VDC ±2 % @ 11 to 24 VDC input, 23 to 24 VDC @ 10 to 11 VDC input"): the
///   output holds the set voltage (6205h.1 within 6205h.3..6205h.2 and 6203h.1); below 11 V input
///   its ceiling falls 1 V per volt (23 V at 10 V input, 21.5 V at the 8.5 V shutdown).
/// - Load: a resistance R draws V/R; a current demand draws its current at the regulated voltage.
///   Above the limit the output runs at constant current: a resistance then sees V = I_lim R, a
///   current demand I_d sees V = V_reg I_lim / I_d (it behaves as the resistance V_reg / I_d).
///   R = 0 is a short circuit: 0 V at the current limit (§3 "Short Circuit ... Self-recovery").
/// - Input current: P_out / (0.94 V_in) (§3 "Efficiency 94 %").

#include <cstdint>

namespace canfleet::devices::ps {

/// The hardware protection of the input stage, with its hysteresis.
class InputProtection {
 public:
  enum class State : std::uint8_t { kOk, kUnderVoltage, kOverVoltage };
  static constexpr double kUnderShutdown_V = 8.5;
  static constexpr double kUnderRecover_V = 11.5;
  static constexpr double kOverShutdown_V = 44.0;
  static constexpr double kOverRecover_V = 42.0;

  /// The input is now `vin_V`; returns the new state.
  State Update(double vin_V);
  /// Power-on: a unit powered up at `vin_V` (below 8.5 V or above 44 V it starts shut down; between
  /// the recovery and shutdown levels it starts running).
  void Reset(double vin_V);
  State state() const { return state_; }
  bool Ok() const { return state_ == State::kOk; }

 private:
  State state_ = State::kOk;
};

/// Fig. 2 (2330h = 0): the current limit for a filtered input voltage.
double ManufacturerCurrentLimit(double vin_V);

struct Load {
  bool is_resistance = true;
  double resistance_ohm = 24.0;
  double current_A = 1.0;
};

struct OutputPoint {
  double voltage_V = 0;
  double current_A = 0;
  double input_current_A = 0;
  bool current_limited = false;
};

/// The output's operating point. `on` false (or a zero set voltage) gives 0 V, 0 A.
OutputPoint Operate(bool on, double set_voltage_V, double vin_V, double limit_A, const Load& load);

}  // namespace canfleet::devices::ps
