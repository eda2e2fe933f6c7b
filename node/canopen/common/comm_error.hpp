#pragma once
/// @file How protocol services report communication errors. A service only says what happened;
/// the stack's error policy (shared with the device) decides the EMCY code, the 1003h entry and
/// the 1029h reaction, because the five manuals encode the same event differently
/// (e.g. heartbeat loss is 0x08nn8130 on the Quad controller).

#include <cstdint>

namespace canfleet::canopen {

enum class CommErrorKind : std::uint8_t {
  kHeartbeatTimeout,   ///< detail = node-ID of the silent producer (1016h); EMCY 8130h
  kLifeGuardTimeout,   ///< node guarding: no guard RTR within guard time × life time factor; EMCY 8130h
  kRpdoTimeout,        ///< detail = RPDO number (1-based); deadline of the RPDO event timer expired; EMCY
                       ///< 8250h/8100h
  kRpdoTooShort,       ///< detail = RPDO number; fewer bytes than mapped; EMCY 8210h, not applied
  kRpdoTooLong,        ///< detail = RPDO number; more bytes than mapped; EMCY 8220h
  kSyncLength,         ///< SYNC with an unexpected DLC; EMCY 8240h
  kBusOff,             ///< own controller bus-off; EMCY 8140h (recovered from bus-off)
  kErrorPassive,       ///< own controller error-passive; EMCY 8120h
  kBootUpOfMonitored,  ///< detail = node-ID: a monitored producer sent boot-up (it was reset)
};

struct CommError {
  CommErrorKind kind;
  std::uint8_t detail = 0;
};

/// Receives communication errors from services. `active` is true when the error appears and false
/// when it goes away (heartbeat back, RPDO back, bus-off recovered).
class CommErrorSink {
 public:
  virtual ~CommErrorSink() = default;
  virtual void OnCommError(const CommError& error, bool active) = 0;
};

}  // namespace canfleet::canopen
