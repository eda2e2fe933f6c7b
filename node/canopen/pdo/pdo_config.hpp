#pragma once
/// @file PDO communication parameters (CiA 301 v4.2 §7.5.2.35 and §7.5.2.37): decoding and the
/// write rules that keep a PDO consistent while it may be in use.

#include <chrono>
#include <cstdint>
#include <span>

#include "node/canopen/od/abort_code.hpp"
#include "node/canopen/od/object_dictionary.hpp"
#include "node/canopen/pdo/pdo_mapping.hpp"
#include "node/canopen/pdo/pdo_objects.hpp"

namespace canfleet::canopen {

/// Sub1 decoded.
struct PdoCobId {
  bool valid = false;        ///< bit 31 clear
  bool rtr_allowed = false;  ///< bit 30 clear
  bool extended = false;     ///< bit 29 set
  std::uint32_t can_id = 0;  ///< bits 10-0, or 28-0 when extended

  static PdoCobId Decode(std::uint32_t raw);
  /// Same identifier on the wire (CAN-ID and frame format).
  bool SameIdentifier(const PdoCobId& other) const {
    return can_id == other.can_id && extended == other.extended;
  }
};

/// One communication record as the service uses it. Missing optional sub-objects read as 0
/// (sub2 as 255, sub1 as "not valid").
struct PdoCommParams {
  std::uint32_t cob_id_raw = kPdoCobIdInvalid;
  PdoCobId cob_id;
  std::uint8_t type = kTransmissionEventProfile;
  std::chrono::microseconds inhibit{0};  ///< sub3 × 100 µs
  std::chrono::milliseconds event_timer{0};
  std::uint8_t sync_start = 0;

  static PdoCommParams Read(const Object& comm);
};

/// True for the event-driven types 254 and 255.
inline bool IsEventDriven(std::uint8_t type) {
  return type >= kTransmissionEventManufacturer;
}
/// True for the synchronous types 0–240.
inline bool IsSynchronous(std::uint8_t type) {
  return type <= kTransmissionSyncMaxCycle;
}
/// True for the types a PDO of this direction can run with: RPDO 0–240, 254, 255; TPDO also
/// 252 and 253 (CiA 301 §7.5.2.35, §7.5.2.37).
bool IsUsableType(PdoDirection direction, std::uint8_t type);

/// 11-bit CAN-IDs reserved by CiA 301 for NMT, SYNC, TIME, EMCY, SDO, heartbeat and LSS
/// (CANopenNode `CO_IS_RESTRICTED_CAN_ID`, facts §1): 000–07Fh, 101–180h, 581–5FFh, 601–67Fh,
/// 6E0–6FFh, 701–7FFh.
bool IsRestrictedPdoCanId(std::uint32_t can_id);

/// Checks a write of sub-index `sub_index` of a communication record whose current contents are
/// `current`. All refusals are kInvalidValue (06090030h):
/// - sub1: bits 28-11 set with an 11-bit CAN-ID; a valid COB-ID with a restricted 11-bit CAN-ID;
///   a change of CAN-ID or frame format while the PDO is and stays valid; for a TPDO, forbidding
///   RTR (bit 30) while the type is 252/253.
/// - sub2: 241–251; for an RPDO 252/253; for a TPDO 252/253 while RTR is not allowed.
/// - sub3 (inhibit time), sub6 (SYNC start value): any write while the PDO is valid; sub6 > 240.
/// Enabling a PDO without mapped objects is allowed (it then sends nothing).
SdoAbort CheckCommWrite(PdoDirection direction, const PdoCommParams& current, std::uint8_t sub_index,
                        std::span<const std::uint8_t> data);

/// The configuration of one PDO: its two records, decoded, with the mapping resolved. Checks
/// writes of either record against the dictionary as it is (validators run before the commit).
class PdoConfig {
 public:
  /// `mapping` may be null (a PDO without a mapping record maps nothing).
  PdoConfig(ObjectDictionary& od, PdoDirection direction, Object& comm, Object* mapping);

  /// Re-reads both records. A mapping that does not resolve (e.g. a device default naming a
  /// missing object) leaves the PDO unusable until it is fixed, as in CANopenNode.
  void Reload();

  /// See CheckCommWrite().
  SdoAbort CheckCommWrite(std::uint8_t sub_index, std::span<const std::uint8_t> data) const;
  /// Mapping record rules (CiA 301 §7.5.2.36, facts §4 "changing a mapping"), all while the PDO
  /// is valid → kInvalidValue (06090030h); an entry (sub1..64) while sub0 ≠ 0 → kInvalidValue;
  /// an entry is checked as CheckMappingEntry(); sub0 = n resolves entries 1..n as ResolveMapping().
  SdoAbort CheckMappingWrite(std::uint8_t sub_index, std::span<const std::uint8_t> data) const;

  PdoDirection direction() const { return direction_; }
  const PdoCommParams& comm() const { return comm_; }
  const PdoMapping& mapping() const { return mapping_; }
  bool mapping_ok() const { return mapping_ok_; }
  Object& comm_record() { return comm_record_; }
  Object* mapping_record() { return mapping_record_; }

  /// Valid COB-ID, a type this direction can run, and a mapping that resolved.
  bool Usable() const { return comm_.cob_id.valid && mapping_ok_ && IsUsableType(direction_, comm_.type); }

 private:
  ObjectDictionary& od_;
  PdoDirection direction_;
  Object& comm_record_;
  Object* mapping_record_;
  PdoCommParams comm_;
  PdoMapping mapping_;
  bool mapping_ok_ = true;
};

}  // namespace canfleet::canopen
