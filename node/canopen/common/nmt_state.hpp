#pragma once
/// @file NMT states with the values they carry in heartbeat and guarding frames (CiA 301 §7.2.8.3.2).

#include <cstdint>

namespace canfleet::canopen {

enum class NmtState : std::uint8_t {
  kInitialising = 0x00,  ///< only ever seen as the boot-up message
  kStopped = 0x04,
  kOperational = 0x05,
  kPreOperational = 0x7F,
};

/// NMT command specifiers (CiA 301 §7.2.8.3.1).
enum class NmtCommand : std::uint8_t {
  kStart = 0x01,
  kStop = 0x02,
  kEnterPreOperational = 0x80,
  kResetNode = 0x81,
  kResetCommunication = 0x82,
};

const char* ToString(NmtState state);

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
