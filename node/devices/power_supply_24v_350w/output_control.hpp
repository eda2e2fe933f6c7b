#pragma once
/// @file The output state machine of the Power Supply Control block (UMAX080311 §1.2.1, §1.2.3):
/// which command is in force, when the output goes off, and when a failure holds it off.
///
/// - Enable-pin deglitch (§1.2.1.2, 2310h): a high pin is taken at once; a low pin only once it has
///   stayed low for 2310h ms ("in addition to any configured shutdown delay").
/// - Source selection (Table 1, 6010h.1): FCh local = the deglitched pin; FDh remote = 6200h.2
///   (Table 2: FCh off, FDh on, FFh keeps the previous state); FFh = whichever CHANGED most
///   recently: a pin edge, or a network write (SDO or RPDO) that changes 6200h.2 to FCh or FDh. A
///   repeated write of the same value is no change, so a cyclic RPDO1 does not override the pin.
///   At power-on the pin's level counts as its latest change. (README.md, choices 1 and 2.)
/// - Delayed shutdown (§1.2.1.1, Fig. 1): an OFF command while the output is on switches it off at
///   once when 2302h = 0; otherwise the output stays on for 2302h ms and EMCY F001h "Shutdown
///   Initialized" (1003h 2000F001h) goes out. A write of 1 to 2301h (RPDO3) during the countdown
///   shortens the remaining time to 2303h unless it is already shorter. An ON command during the
///   countdown cancels it (Fig. 1's "Command HI" path). The F001h error ends (EMCY 0000h, 1003h entry
///   removed) when the countdown ends either way. 2301h is set back to 0 when a countdown starts.
/// - Failures (§1.2.3): an active input or output failure (FF04h/FF06h) switches the output off at
///   once, without a countdown. With 2320h = 0 the output follows its command again when the failure
///   clears; with 2320h = 1 the unit stays in its fault state until a Quit Failure (FCh written to
///   6200h.3, Table 6, or to 6010h.2) arrives while no failure is active.
///
/// The block decides whether the firmware enables the power stage; the hardware input protection
/// (power_model.hpp) may still hold the stage off.

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

#include "clock/scheduler.hpp"
#include "node/canopen/stack/canopen_stack.hpp"
#include "node/devices/od_ref.hpp"

namespace canfleet::devices::ps {

enum class OutputState : std::uint8_t {
  kOff,            ///< commanded off
  kOn,             ///< delivering
  kShutdownDelay,  ///< commanded off, on until the countdown ends (§1.2.1.1)
  kFault,          ///< held off by an active input/output failure (§1.2.3)
  kFaultLatched,   ///< held off until Quit Failure (2320h = 1)
  kProtection,     ///< commanded on, held off by the hardware input protection (§3)
};
inline constexpr std::array<OutputState, 6> kOutputStates = {
    OutputState::kOff,   OutputState::kOn,           OutputState::kShutdownDelay,
    OutputState::kFault, OutputState::kFaultLatched, OutputState::kProtection};
/// "off", "on", "shutdown_delay", "fault", "fault_latched", "protection" (PS.state).
std::string_view StateName(OutputState state);

class OutputControl {
 public:
  explicit OutputControl(canopen::CanopenStack& stack);

  /// Power-on (reset application): no countdown, no latch; the pin as it is counts as the latest
  /// change; 6200h.2 as restored is the last network value.
  void Reset(bool pin_high);

  /// 6200h.2 was written by the network (SDO/RPDO) with `value`.
  void OnCanCommand(std::uint8_t value);
  /// FCh was written to 6200h.3 or 6010h.2.
  void OnQuitFailure() { quit_requested_ = true; }
  /// 2301h was written by the network with `value`.
  void OnShutdownAck(std::uint8_t value, TimePoint now);

  struct Inputs {
    bool pin_high = false;  ///< the Enable pin as sampled now
    bool failure = false;   ///< FF04h or FF06h active
    bool input_ok = true;   ///< no hardware under/over-voltage shutdown
  };
  /// One step of the 1 ms control loop. True if the command, the output or the state changed.
  bool Update(const Inputs& in, TimePoint now);

  /// The firmware enables the power stage.
  bool Enabled() const { return enabled_; }
  bool CommandOn() const { return command_; }
  bool Latched() const { return latched_; }
  bool ShuttingDown() const { return shutdown_at_.has_value(); }
  bool Failure() const { return failure_; }
  OutputState State() const;
  /// A delay is counting: a low pin being deglitched, or a shutdown countdown.
  bool Pending() const { return low_since_.has_value() || shutdown_at_.has_value(); }

 private:
  void EndShutdown();

  canopen::CanopenStack& stack_;
  OdRef control_mode_, on_off_, base_delay_, ack_delay_, ack_, deglitch_, latch_enable_;
  bool pin_ = false;  // deglitched
  std::optional<TimePoint> low_since_;
  Duration low_delay_{};
  std::uint8_t last_can_value_ = 0xFF;
  bool last_change_on_ = false;
  bool command_ = false;
  bool enabled_ = false;
  bool latched_ = false;
  bool quit_requested_ = false;
  bool failure_ = false;
  bool input_ok_ = true;
  std::optional<TimePoint> shutdown_at_;
};

}  // namespace canfleet::devices::ps
