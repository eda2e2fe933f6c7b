#pragma once
/// @file Which services of the stack run in which NMT state. The states themselves are shared
/// vocabulary (vocabulary/nmt_state.hpp).

#include "vocabulary/nmt_state.hpp"

namespace canfleet::canopen {

/// Which services may run in a state (CiA 301 §7.3.2.2, table 51): in Stopped only NMT, node
/// guarding/heartbeat and LSS; SDO, EMCY, SYNC and TIME also in Pre-operational; PDO only in Operational.
inline bool SdoAllowed(NmtState s) {
  return s == NmtState::kPreOperational || s == NmtState::kOperational;
}
inline bool EmcyAllowed(NmtState s) {
  return SdoAllowed(s);
}
inline bool SyncAllowed(NmtState s) {
  return SdoAllowed(s);
}
inline bool PdoAllowed(NmtState s) {
  return s == NmtState::kOperational;
}

}  // namespace canfleet::canopen
