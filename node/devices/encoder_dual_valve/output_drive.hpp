#pragma once
/// @file One output drive of the AX023241 (1.4, Tables 8-12, Figures 5-7, 1.5 "fault detection",
/// 4.3): what the output is commanded to do and what its high-side driver then puts on the load.
/// No dictionary here: valve_outputs.hpp reads the objects and feeds this model.
///
/// Command, per evaluation, in this order (README.md "Outputs"):
///   1. disabled type (6310h = 0) or a shutdown (supply/temperature fault, NMT stopped, a CAN
///      controlled output outside operational): off at once, no ramp.
///   2. a fault on an active control/enable/override input -> Control Fault Response (Table 12,
///      object 6340h): 0 shut off, 1 apply the fault value 7341h, 2 hold the last value; digital
///      types use the DS-404 DO objects: 6250h TRUE applies the state 6260h, FALSE holds.
///   3. override (2360h/2361h) active, i.e. its input On (2362h = 0) or Off (2362h = 1): the
///      override value 2300h regardless of the control input.
///   4. enable (2350h/2351h) in use and Off: Enable Response 0 "Enable When On, Else Shutoff"
///      (Table 10; the response has no object, so it is its first option).
///   5. control (2340h/2341h): the source normalised to 0..1 by its limits, then linear between
///      the FV limits 7321h (0 %) and 7323h (100 %) (1.4 "scaled ... between 0 and 1", Figure 7);
///      control source 0 follows 7330h as written (digital types: 6200h bit XOR 6202h bit).
///   A source is On when it is set, not in error and its value is not 0 (as the lookup table reads
///   its X source as digital, blocks/lookup_table.hpp).
/// The target is held to the FV limits and the type's range: current 0-2500 mA, voltage 0-60 V,
/// PWM 0-100 %, digital 0/1 (Table 8), in FV units with 6332h decimals.
///
/// Time: proportional types ramp to the target at |7323h - 7321h| / 2330h (up) or 2331h (down)
/// per ms (1.4; the type's range when the FV limits are equal; 0 ms = a step). Digital types delay
/// the edge 2225h names (1 = OFF->ON, 0 = ON->OFF) by 2224h ms. A hotshot output drives 2000 mA
/// for 1000 ms after each OFF->ON, then holds 500 mA (Figure 5; the manual's Hotshot Current,
/// Hotshot Time and Hold Current objects do not exist, so the family's valve defaults apply).
///
/// Driver (4.3): current types regulate up to what the supply can push through the coil
/// (Vps / R); voltage and PWM switch Vps at 25 kHz / 2380h; digital switches Vps. A shorted load,
/// or a switched load whose peak current Vps / R passes 4 A, trips the hardware protection: the
/// driver is off, and is tried again every 1000 ms while still commanded (1.5 "periodically try
/// to re-engage"), resuming when the short is gone. An open load keeps being driven, no current.

#include <chrono>
#include <cstdint>
#include <optional>

#include "node/devices/blocks/signal.hpp"
#include "node/devices/encoder_dual_valve/encoder_objects.hpp"

namespace canfleet::devices::encoder {

enum class LoadState : std::uint8_t { kNominal, kOpen, kShort };

/// A control, enable or override input: `used` = its source object is not 0.
struct DriveSource {
  bool used = false;
  blocks::Signal signal = blocks::Signal::NotAvailable();
  bool On() const { return signal.available && !signal.error && signal.value != 0.0; }
  bool Faulted() const { return used && signal.error; }
};

struct DriveConfig {
  OutputType type = OutputType::kCurrent;
  double fv_min = 0.0;               ///< 7321h (FV units)
  double fv_max = 5000.0;            ///< 7323h
  std::uint8_t fv_digits = 0;        ///< 6332h
  std::int64_t ramp_up_ms = 1000;    ///< 2330h
  std::int64_t ramp_down_ms = 1000;  ///< 2331h
  double override_fv = 0.0;          ///< 2300h
  bool override_when_off = false;    ///< 2362h = 1
  std::uint8_t fault_response = 0;   ///< 6340h (Table 12)
  double fault_fv = 500.0;           ///< 7341h
  bool do_fault_apply = true;        ///< 6250h
  bool do_fault_state = false;       ///< 6260h
  std::int64_t delay_ms = 0;         ///< 2224h
  bool delay_on_edge = false;        ///< 2225h = 1: the OFF->ON edge is delayed
};

struct DriveCommand {
  DriveSource control;
  DriveSource enable;
  DriveSource override_input;
  bool direct = false;     ///< control source 0
  double direct_fv = 0.0;  ///< 7330h as the master wrote it
  bool direct_on = false;  ///< 6200h bit XOR 6202h bit
  bool shutdown = false;
};

struct LoadModel {
  double supply_V = 24.0;
  LoadState load = LoadState::kNominal;
  double resistance_ohm = 8.0;
  double pwm_frequency_Hz = 25000.0;
};

struct DriveOutput {
  double target_fv = 0.0;   ///< 7330h: the commanded field value
  double desired_mA = 0.0;  ///< current types: the current the regulator aims at
  bool driving = false;     ///< the output is commanded to put something on the load
  bool on = false;
  bool tripped = false;
  bool hotshot = false;
  double current_mA = 0.0;
  double voltage_V = 0.0;
  double duty_pct = 0.0;
  double frequency_Hz = 0.0;
};

/// Table 8's range of `type` in engineering units (mA, V, %, 0/1).
double TypeRange(OutputType type);
bool IsProportional(OutputType type);
bool IsDigital(OutputType type);
bool IsCurrentControlled(OutputType type);

class OutputDrive {
 public:
  using Ms = std::chrono::milliseconds;
  static constexpr Ms kRetryPeriod{1000};
  static constexpr Ms kHotshotTime{1000};
  static constexpr double kHotshotCurrent_mA = 2000.0;
  static constexpr double kHoldCurrent_mA = 500.0;
  static constexpr double kTripCurrent_mA = 4000.0;
  static constexpr double kDriverFrequency_Hz = 25000.0;

  /// One evaluation, `elapsed` after the previous one.
  void Step(Ms elapsed, const DriveConfig& config, const DriveCommand& command, const LoadModel& load);
  const DriveOutput& Output() const { return out_; }
  /// When another evaluation can change the output with the inputs as they are: 1 ms while
  /// ramping, the rest of a delay, hotshot phase or retry period; nullopt when settled.
  std::optional<Ms> NextChange() const;
  void Reset();

 private:
  enum class Kind : std::uint8_t { kOff, kSet, kHold, kFollow };
  void StepProportional(Ms elapsed, const DriveConfig& config, Kind kind, double value);
  void StepDigital(Ms elapsed, const DriveConfig& config, Kind kind, bool on);
  void Drive(Ms elapsed, const DriveConfig& config, const LoadModel& load);

  double present_ = 0.0;  ///< FV after the ramp
  double target_ = 0.0;
  bool ramping_ = false;
  bool requested_on_ = false;
  bool commanded_on_ = false;
  bool delay_running_ = false;
  Ms delay_left_{0};
  bool hotshot_running_ = false;
  Ms hotshot_left_{0};
  bool tripped_ = false;
  Ms retry_left_{0};
  DriveOutput out_;
};

}  // namespace canfleet::devices::encoder
