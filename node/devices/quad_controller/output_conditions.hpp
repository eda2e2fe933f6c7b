#pragma once
/// @file What decides the outputs besides their own control (AX020506 §4.2): the NMT state and the
/// controller fault state.

#include "node/canopen/common/nmt_state.hpp"

namespace canfleet::devices::quad {

struct OutputConditions {
  canopen::NmtState nmt = canopen::NmtState::kInitialising;
  /// Controller fault state: at least one active fault (an entry in the error list, including a
  /// lost heartbeat). Outputs then follow 6206h/6207h (DO) and 6340h/7341h (AO).
  bool fault_state = false;
  /// The fault state began at this tick (6340h = 1 writes 7341h into 7330h once).
  bool fault_entered = false;

  bool Stopped() const { return nmt == canopen::NmtState::kStopped; }
  /// Outputs controlled by the CANopen message run only in operational (§4.2 "Pre-Operational
  /// Behaviour": such an output is always off); before boot-up nothing runs either.
  bool CanControlAllowed() const { return nmt == canopen::NmtState::kOperational; }
};

}  // namespace canfleet::devices::quad
