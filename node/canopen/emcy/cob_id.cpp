#include "node/canopen/emcy/cob_id.hpp"

namespace canfleet::canopen {

namespace {

// 11-bit CAN-IDs that CiA 301 keeps for NMT, the default SDO channels, heartbeat, LSS and the
// like; SYNC, TIME, EMCY, PDO and SDO COB-IDs must not use them (CANopenNode
// CO_IS_RESTRICTED_CAN_ID): 000h-07Fh, 101h-180h, 581h-5FFh, 601h-67Fh, 6E0h-6FFh, 701h-7FFh.
bool IsRestrictedCanId(std::uint32_t id) {
  return id <= 0x07F || (id >= 0x101 && id <= 0x180) || (id >= 0x581 && id <= 0x5FF) ||
         (id >= 0x601 && id <= 0x67F) || (id >= 0x6E0 && id <= 0x6FF) || (id >= 0x701 && id <= 0x7FF);
}

}  // namespace

EmcyCobId EmcyCobId::Decode(std::uint32_t value) {
  EmcyCobId c;
  c.valid = (value & kEmcyCobIdInvalid) == 0;
  c.extended = (value & kEmcyCobIdExtended) != 0;
  c.can_id = value & (c.extended ? 0x1FFFFFFFu : 0x7FFu);
  return c;
}

std::uint32_t EmcyCobId::Encode() const {
  return (valid ? 0 : kEmcyCobIdInvalid) | (extended ? kEmcyCobIdExtended : 0) | can_id;
}

SdoAbort ValidateEmcyCobIdWrite(std::uint32_t current, std::uint32_t requested) {
  if ((requested & kEmcyCobIdReserved) != 0) return SdoAbort::kInvalidValue;
  const bool extended = (requested & kEmcyCobIdExtended) != 0;
  if (!extended) {
    if ((requested & 0x1FFFF800u) != 0) return SdoAbort::kInvalidValue;
    if (IsRestrictedCanId(requested & 0x7FFu)) return SdoAbort::kInvalidValue;
  }
  const bool was_valid = (current & kEmcyCobIdInvalid) == 0;
  const bool now_valid = (requested & kEmcyCobIdInvalid) == 0;
  constexpr std::uint32_t kIdentity = kEmcyCobIdExtended | 0x1FFFFFFFu;
  if (was_valid && now_valid && (current & kIdentity) != (requested & kIdentity))
    return SdoAbort::kInvalidValue;
  return SdoAbort::kNone;
}

}  // namespace canfleet::canopen
