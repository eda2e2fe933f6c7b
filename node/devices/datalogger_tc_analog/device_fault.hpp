#pragma once
/// @file A fault of the data logger's application (an input out of span, an open thermocouple, a
/// supply out of range ...), reported on every CAN port.
///
/// The two ports have "separate Communication Objects" (UMAX181001 §3), so each has its own EMCY
/// producer, 1001h, 1003h and 1029h; the manual does not say which port reports a device fault.
/// Policy (README "Faults on two ports"): the device's faults concern the one set of application
/// objects both ports share, so both ports report them: one DelayedFault per port, each with its
/// port's EMCY/1003h and its port's 1029h reaction. Communication faults stay with the port they
/// happen on (the stacks handle those).
///
/// Delays are counted by the blocks (the span monitor's 2112h); a DeviceFault becomes active on
/// the cycle its condition is reported and clears on the first cycle it is gone.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "clock/scheduler.hpp"
#include "node/canopen/stack/canopen_stack.hpp"
#include "node/devices/delayed_fault.hpp"

namespace canfleet::devices::datalogger {

class DeviceFault {
 public:
  /// @param behaviour_sub 1029h sub-index of each port's reaction (0 = none).
  DeviceFault(Scheduler& scheduler, std::span<canopen::CanopenStack* const> stacks, canopen::ErrorEntry entry,
              std::uint8_t behaviour_sub);

  /// The condition as evaluated now (every port follows it).
  void Set(bool present);
  /// Port `port` was reset (its stack forgot its errors): its record starts inactive.
  void ResetPort(std::size_t port);

  bool Active(std::size_t port = 0) const { return ports_.at(port)->Active(); }
  const canopen::ErrorEntry& entry() const { return ports_.front()->entry(); }

 private:
  std::vector<std::unique_ptr<DelayedFault>> ports_;
};

}  // namespace canfleet::devices::datalogger
