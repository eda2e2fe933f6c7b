#pragma once
/// @file An I/O fault with the life cycle the device manuals share (Quad AX020506 §4.2; the valve,
/// encoder and data logger manuals describe the same with their own delay objects):
///
///   inactive --condition seen--> pending (timer = the channel's error response delay)
///   pending  --condition gone--> inactive (the timer stops)
///   pending  --timer expires---> active: EMCY + 1003h entry + 1001h, then the 1029h reaction
///   active   --condition gone--> inactive: error reset EMCY, entry removed from 1003h
///
/// A delay of 0 activates at once. The fault does not sample anything itself: the device reports
/// the condition on each of its ticks through Update().

#include <cstdint>

#include "clock/scheduler.hpp"
#include "node/canopen/emcy/error_entry.hpp"
#include "node/canopen/stack/canopen_stack.hpp"

namespace canfleet::devices {

/// Applies the error behaviour of 1029h sub-index `sub` (CiA 301 §7.5.2.32) for a device error:
/// 0 = enter pre-operational (only from operational), 1 = no change, 2 = enter stopped. Without
/// that sub-index nothing happens (1029h is mandatory only for communication errors).
void ApplyErrorBehaviour(canopen::CanopenStack& stack, std::uint8_t sub);

class DelayedFault {
 public:
  enum class State : std::uint8_t { kInactive, kPending, kActive };

  /// @param entry what goes to EMCY/1003h when the fault becomes active.
  /// @param behaviour_sub the 1029h sub-index deciding the NMT reaction (0 = none).
  DelayedFault(Scheduler& scheduler, canopen::CanopenStack& stack, canopen::ErrorEntry entry,
               std::uint8_t behaviour_sub);
  DelayedFault(const DelayedFault&) = delete;
  DelayedFault& operator=(const DelayedFault&) = delete;

  /// Reports the condition as sampled now. `delay` is the channel's current error response delay;
  /// it is loaded when the fault enters pending. Returns true if the state changed (on-demand
  /// ticks: a fault whose condition stays as it is needs no further Update until it changes).
  bool Update(bool present, Duration delay);
  /// Back to inactive without an EMCY: reset application (the stack already forgot its errors).
  void Reset();

  State state() const { return state_; }
  bool Active() const { return state_ == State::kActive; }
  const canopen::ErrorEntry& entry() const { return entry_; }

 private:
  void Activate();

  canopen::CanopenStack& stack_;
  canopen::ErrorEntry entry_;
  std::uint8_t behaviour_sub_;
  State state_ = State::kInactive;
  Timer timer_;
};

}  // namespace canfleet::devices
