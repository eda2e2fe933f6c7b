#include "node/canopen/pdo/pdo_config.hpp"

namespace canfleet::canopen {

namespace {

constexpr std::uint32_t kExtendedIdMask = 0x1FFFFFFF;
constexpr std::uint32_t kStandardIdMask = 0x7FF;

std::uint64_t ValueOf(const Object& record, std::uint8_t sub_index, std::uint64_t fallback) {
  auto it = record.subs.find(sub_index);
  return it == record.subs.end() ? fallback : DecodeUnsignedLe(it->second.value);
}

bool IsRtrType(std::uint8_t type) {
  return type == kTransmissionRtrSync || type == kTransmissionRtrEvent;
}

}  // namespace

PdoCobId PdoCobId::Decode(std::uint32_t raw) {
  PdoCobId id;
  id.valid = (raw & kPdoCobIdInvalid) == 0;
  id.rtr_allowed = (raw & kPdoCobIdNoRtr) == 0;
  id.extended = (raw & kPdoCobIdFrame) != 0;
  id.can_id = raw & (id.extended ? kExtendedIdMask : kStandardIdMask);
  return id;
}

PdoCommParams PdoCommParams::Read(const Object& comm) {
  PdoCommParams p;
  p.cob_id_raw = static_cast<std::uint32_t>(ValueOf(comm, 1, kPdoCobIdInvalid));
  p.cob_id = PdoCobId::Decode(p.cob_id_raw);
  p.type = static_cast<std::uint8_t>(ValueOf(comm, 2, kTransmissionEventProfile));
  p.inhibit = std::chrono::microseconds(100 * static_cast<std::int64_t>(ValueOf(comm, 3, 0)));
  p.event_timer = std::chrono::milliseconds(static_cast<std::int64_t>(ValueOf(comm, 5, 0)));
  p.sync_start = static_cast<std::uint8_t>(ValueOf(comm, 6, 0));
  return p;
}

bool IsUsableType(PdoDirection direction, std::uint8_t type) {
  if (IsSynchronous(type) || IsEventDriven(type)) return true;
  return direction == PdoDirection::kTransmit && IsRtrType(type);
}

bool IsRestrictedPdoCanId(std::uint32_t id) {
  return id <= 0x7F || (id >= 0x101 && id <= 0x180) || (id >= 0x581 && id <= 0x5FF) ||
         (id >= 0x601 && id <= 0x67F) || (id >= 0x6E0 && id <= 0x6FF) || id >= 0x701;
}

// Rules of CANopenNode `301/CO_PDO.c` (OD_write_14xx/OD_write_18xx) and LELY `src/co/tpdo.c`
// (co_1800_dn_ind), with LELY's 29-bit frame bit and RTR-only types.
SdoAbort CheckCommWrite(PdoDirection direction, const PdoCommParams& current, std::uint8_t sub_index,
                        std::span<const std::uint8_t> data) {
  const auto value = DecodeUnsignedLe(data);
  const bool valid = current.cob_id.valid;
  switch (sub_index) {
    case 1: {
      const auto raw = static_cast<std::uint32_t>(value);
      const PdoCobId next = PdoCobId::Decode(raw);
      if (!next.extended && (raw & (kExtendedIdMask & ~kStandardIdMask)) != 0) return SdoAbort::kInvalidValue;
      if (next.valid && !next.extended && IsRestrictedPdoCanId(next.can_id)) return SdoAbort::kInvalidValue;
      if (valid && next.valid && !next.SameIdentifier(current.cob_id)) return SdoAbort::kInvalidValue;
      if (direction == PdoDirection::kTransmit && !next.rtr_allowed && IsRtrType(current.type)) {
        return SdoAbort::kInvalidValue;
      }
      return SdoAbort::kNone;
    }
    case 2: {
      const auto type = static_cast<std::uint8_t>(value);
      if (!IsUsableType(direction, type)) return SdoAbort::kInvalidValue;
      if (IsRtrType(type) && !current.cob_id.rtr_allowed) return SdoAbort::kInvalidValue;
      return SdoAbort::kNone;
    }
    case 3:
      return valid ? SdoAbort::kInvalidValue : SdoAbort::kNone;
    case 6:
      return valid || value > kTransmissionSyncMaxCycle ? SdoAbort::kInvalidValue : SdoAbort::kNone;
    default:
      return SdoAbort::kNone;
  }
}

PdoConfig::PdoConfig(ObjectDictionary& od, PdoDirection direction, Object& comm, Object* mapping)
    : od_(od), direction_(direction), comm_record_(comm), mapping_record_(mapping) {
  Reload();
}

void PdoConfig::Reload() {
  comm_ = PdoCommParams::Read(comm_record_);
  if (!mapping_record_) {
    mapping_.Clear();
    mapping_ok_ = true;
    return;
  }
  const auto count = static_cast<std::uint8_t>(ValueOf(*mapping_record_, 0, 0));
  mapping_ok_ = ResolveMapping(od_, direction_, *mapping_record_, count, mapping_) == SdoAbort::kNone;
  if (!mapping_ok_) mapping_.Clear();
}

SdoAbort PdoConfig::CheckCommWrite(std::uint8_t sub_index, std::span<const std::uint8_t> data) const {
  return canopen::CheckCommWrite(direction_, PdoCommParams::Read(comm_record_), sub_index, data);
}

SdoAbort PdoConfig::CheckMappingWrite(std::uint8_t sub_index, std::span<const std::uint8_t> data) const {
  if (!mapping_record_) return SdoAbort::kNone;
  if (PdoCommParams::Read(comm_record_).cob_id.valid) return SdoAbort::kInvalidValue;
  const auto value = DecodeUnsignedLe(data);
  if (sub_index == 0) {
    PdoMapping scratch;
    return ResolveMapping(od_, direction_, *mapping_record_, static_cast<std::uint8_t>(value), scratch);
  }
  if (ValueOf(*mapping_record_, 0, 0) != 0) return SdoAbort::kInvalidValue;
  MappedObject entry;
  return CheckMappingEntry(od_, direction_, static_cast<std::uint32_t>(value), entry);
}

}  // namespace canfleet::canopen
