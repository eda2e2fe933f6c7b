#include "node/canopen/stack/error_policy.hpp"

namespace canfleet::canopen {

// EMCY codes of CiA 301 §7.2.7.1 table 21; the 1003h manufacturer part carries the detail
// (node-ID or PDO number) so that two heartbeat losses are two entries.
std::optional<CommErrorEncoding> ErrorPolicy::Encode(const CommError& error) const {
  CommErrorEncoding e;
  e.entry.register_bits = kErrorRegisterCommunication;
  e.entry.info = error.detail;
  e.entry.msef[0] = error.detail;
  switch (error.kind) {
    case CommErrorKind::kHeartbeatTimeout:
    case CommErrorKind::kLifeGuardTimeout:
      e.entry.code = 0x8130;
      break;
    case CommErrorKind::kRpdoTimeout:
      e.entry.code = 0x8250;
      break;
    case CommErrorKind::kRpdoTooShort:
      e.entry.code = 0x8210;
      e.behaviour_sub = 0;
      break;
    case CommErrorKind::kRpdoTooLong:
      e.entry.code = 0x8220;
      e.behaviour_sub = 0;
      break;
    case CommErrorKind::kSyncLength:
      e.entry.code = 0x8240;
      e.behaviour_sub = 0;
      break;
    case CommErrorKind::kBusOff:
      e.entry.code = 0x8140;
      break;
    case CommErrorKind::kErrorPassive:
      e.entry.code = 0x8120;
      e.behaviour_sub = 0;
      break;
    case CommErrorKind::kBootUpOfMonitored:
      // A monitored node that reboots is an event, not a lasting error (CiA 301 §7.2.8.3.2.2):
      // reported as heartbeat event EMCY but kept out of the NMT reaction.
      e.entry.code = 0x8130;
      e.behaviour_sub = 0;
      break;
  }
  return e;
}

}  // namespace canfleet::canopen
