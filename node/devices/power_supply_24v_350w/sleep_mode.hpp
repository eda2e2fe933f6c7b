#pragma once
/// @file Sleep mode (UMAX080311 §1.2.2, 2311h): "if during regular operation the power supply is
/// commanded OFF, the controller will wait the amount of time (in milliseconds) specified in object
/// 2311h PS Sleep Delay before going to sleep. The controller will wake upon receiving a CAN frame,
/// or when the Remote Enable signal changes state. If the device NMT state is in Operational Mode
/// the device will not go to sleep."
///
/// Asleep, the node's port is muted (no heartbeat, EMCY, SDO answer or PDO leaves it) and the
/// control loop does not run. Any received frame wakes it before the stack sees that frame, so the
/// frame is served (README.md, choice 12); so does a change of the Enable pin.

#include <functional>

#include "clock/scheduler.hpp"
#include "node/devices/device_port.hpp"

namespace canfleet::devices::ps {

class SleepMode {
 public:
  /// `on_change(asleep)` runs when the controller falls asleep or wakes.
  SleepMode(Scheduler& scheduler, DevicePort& port, std::function<void(bool)> on_change);
  SleepMode(const SleepMode&) = delete;
  SleepMode& operator=(const SleepMode&) = delete;

  /// Whether sleep is allowed now (2311h > 0, commanded off, output off, not operational). The
  /// delay of `delay` starts when it becomes allowed and stops when it no longer is.
  void Update(bool allowed, Duration delay);
  /// A frame arrived or the Enable pin changed.
  void Wake();
  /// Power-on: awake, no delay running.
  void Reset();
  bool Asleep() const { return asleep_; }

 private:
  void FallAsleep();

  DevicePort& port_;
  std::function<void(bool)> on_change_;
  bool allowed_ = false;
  bool asleep_ = false;
  Timer timer_;
};

}  // namespace canfleet::devices::ps
