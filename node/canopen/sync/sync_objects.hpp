#pragma once
/// @file The SYNC objects of CiA 301 v4.2 (§7.5.2.5 1005h COB-ID SYNC, §7.5.2.6 1006h communication
/// cycle period, §7.5.2.7 1007h synchronous window length, 1019h synchronous counter overflow value)
/// and the write rules that guard them.
///
/// 1005h COB-ID SYNC, UNSIGNED32:
///   bit 31: do not care   bit 30: 1 = this node produces SYNC   bit 29: 1 = 29-bit CAN-ID
///   bits 28-11: 0 for an 11-bit CAN-ID   bits 10-0 (or 28-0): CAN-ID (default 080h)
/// 1019h, UNSIGNED8: 0 = SYNC without data (DLC 0); 1 reserved; 2..240 = SYNC carries a counter
///   byte (DLC 1) running 1..value and back to 1; 241..255 reserved.

#include <cstdint>
#include <span>

#include "node/canopen/od/abort_code.hpp"
#include "node/canopen/od/object_dictionary.hpp"

namespace canfleet::canopen {

inline constexpr std::uint16_t kCobIdSyncIndex = 0x1005;
inline constexpr std::uint16_t kCommunicationCyclePeriodIndex = 0x1006;
inline constexpr std::uint16_t kSyncWindowLengthIndex = 0x1007;
inline constexpr std::uint16_t kSyncCounterOverflowIndex = 0x1019;

/// 1005h default: consumer on the pre-defined connection set's SYNC identifier.
inline constexpr std::uint32_t kDefaultSyncCobId = 0x080;

/// 1005h decoded.
struct SyncCobId {
  bool producer = false;  ///< bit 30
  bool extended = false;  ///< bit 29
  std::uint32_t can_id = kDefaultSyncCobId;

  static SyncCobId Decode(std::uint32_t raw);
};

/// The counter byte is present for 1019h = 2..240 (values written by the device itself outside
/// that range are treated as "no counter").
inline bool SyncCounterInUse(std::uint8_t overflow) {
  return overflow >= 2 && overflow <= 240;
}

/// Rules for a write of 1005h (after CANopenNode `301/CO_SYNC.c` OD_write_1005, with LELY's 29-bit
/// frame bit): bits 28-11 set with an 11-bit CAN-ID, a restricted 11-bit CAN-ID (facts §1), or a
/// CAN-ID change while this node produces and keeps producing → kInvalidValue (06090030h).
SdoAbort CheckSyncCobIdWrite(std::uint32_t current, std::uint32_t requested);

/// Rules for a write of 1019h: 1 or > 240 → kInvalidValue (06090030h); any value while 1006h ≠ 0 →
/// kDeviceState (08000022h), because the counter may only change while no SYNC is produced.
SdoAbort CheckSyncCounterOverflowWrite(std::uint8_t requested, std::uint32_t period_us);

/// Adds 1005h (U32 rw, 080h), 1007h (U32 rw µs, 0 = no window) and 1019h (U8 rw, 0) — what a SYNC
/// consumer uses — and, if `with_producer_objects`, 1006h (U32 rw µs, 0 = no SYNC produced).
/// None is PDO-mappable.
void AddSyncObjects(ObjectDictionary& od, bool with_producer_objects);

}  // namespace canfleet::canopen
