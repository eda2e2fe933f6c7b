#pragma once
/// @file The EMCY COB-ID object 1014h (CiA 301 v4.2 §7.5.2.17): decoding and the checks on an SDO
/// write, as CANopenNode's OD_write_1014 does them.
///
/// 1014h, UNSIGNED32:
///   bit 31     0 = EMCY exists / is valid, 1 = EMCY does not exist / is not valid
///   bit 30     reserved (0)
///   bit 29     0 = 11-bit CAN-ID (CAN base frame), 1 = 29-bit CAN-ID (CAN extended frame)
///   bits 28-0  CAN-ID (bits 28-11 are 0 for an 11-bit CAN-ID)

#include <cstdint>

#include "node/canopen/od/abort_code.hpp"

namespace canfleet::canopen {

inline constexpr std::uint32_t kEmcyCobIdInvalid = 0x80000000;
inline constexpr std::uint32_t kEmcyCobIdReserved = 0x40000000;
inline constexpr std::uint32_t kEmcyCobIdExtended = 0x20000000;
/// The EMCY function code of the predefined connection set: COB-ID 80h + node-ID.
inline constexpr std::uint32_t kEmcyFunctionCode = 0x080;

/// The parts of a 1014h value.
struct EmcyCobId {
  bool valid = true;
  bool extended = false;
  std::uint32_t can_id = 0;  ///< bits 28-0 (29-bit) or 10-0 (11-bit)

  static EmcyCobId Decode(std::uint32_t value);
  std::uint32_t Encode() const;
};

/// Checks an SDO/PDO write of 1014h. `current` is the value 1014h reads now (node-ID applied).
/// kInvalidValue (06090030h) for: the reserved bit 30; bits 28-11 with an 11-bit ID; a restricted
/// 11-bit CAN-ID (checked whether or not bit 31 is set, as CANopenNode does, so 80000000h is
/// refused); a CAN-ID or frame-format change while both the old and new value are valid
/// (CiA 301 §7.5.2.17: bits 0-29 shall not be changed while bit 31 = 0).
SdoAbort ValidateEmcyCobIdWrite(std::uint32_t current, std::uint32_t requested);

}  // namespace canfleet::canopen
