#pragma once
/// @file Load diagnosis of one output (AX020506 §2.5, §2.6, §4.1): a short circuit (EMCY 2320h)
/// and an open circuit (3300h), each through the pending → active life cycle with the output's
/// error response delay. The manual gives no detection thresholds; the emulator takes the load
/// state of the simulated I/O and diagnoses it whether or not the output is driven (as drivers
/// with off-state diagnostics do), so a fault clears as soon as the load is repaired.

#include <cstdint>

#include "clock/scheduler.hpp"
#include "node/canopen/stack/canopen_stack.hpp"
#include "node/devices/delayed_fault.hpp"
#include "node/devices/simulated_io.hpp"

namespace canfleet::devices::quad {

class LoadFaults {
 public:
  /// @param description 02h (digital output) or 04h (proportional output); @param channel 1-based.
  LoadFaults(Scheduler& scheduler, canopen::CanopenStack& stack, std::uint8_t description,
             std::uint8_t channel, std::uint8_t behaviour_sub);

  /// `monitored` false clears both (the output is in the other block's mode). Returns true if
  /// either fault changed state.
  bool Update(bool monitored, const IoSignal& load, Duration delay);
  void Reset();

 private:
  DelayedFault short_;
  DelayedFault open_;
};

}  // namespace canfleet::devices::quad
