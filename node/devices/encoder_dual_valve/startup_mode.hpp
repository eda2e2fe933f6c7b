#pragma once
/// @file Start-up of the AX023241 (1.5 "Startup", C3-1.4.70/1.4.71): 5555h Start in Operational
/// Mode and 5556h Start in Operational NMT Delay.
///   5555h = 0  boot into pre-operational and wait for the master (default; "disabled (FALSE)")
///   5555h = 1  "Start directly in operational mode"
///   5555h = 2  "Start in operational mode and send NMT for starting also other devices": 5556h ms
///              (default 1000) after each boot the device sends NMT Start to all nodes,
///              000h [01 00], from its own port (DevicePort::SendFromDevice)
///   5555h = 3  in the printed range 0-3 without a meaning: treated as 0 (README.md)
/// A boot is the change Initialising -> pre-operational/operational (power-on, NMT reset node or
/// reset communication, LSS): a reset before the delay has run cancels the pending NMT Start.

#include "clock/scheduler.hpp"
#include "node/canopen/common/nmt_state.hpp"
#include "node/canopen/od/object_dictionary.hpp"
#include "node/devices/device_port.hpp"

namespace canfleet::devices::encoder {

class StartupMode {
 public:
  StartupMode(Scheduler& scheduler, canopen::ObjectDictionary& od, DevicePort& port);
  StartupMode(const StartupMode&) = delete;
  StartupMode& operator=(const StartupMode&) = delete;

  /// 5555h as read at boot (the stack's start_operational predicate).
  static bool StartOperational(const canopen::ObjectDictionary& od);
  /// Every NMT state change of the device's stack.
  void OnStateChanged(canopen::NmtState state);
  /// An NMT Start is waiting for its delay.
  bool Pending() const { return timer_.Armed(); }

 private:
  canopen::ObjectDictionary& od_;
  DevicePort& port_;
  Timer timer_;
  canopen::NmtState last_ = canopen::NmtState::kInitialising;
};

}  // namespace canfleet::devices::encoder
