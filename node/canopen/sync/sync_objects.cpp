#include "node/canopen/sync/sync_objects.hpp"

#include <string>

namespace canfleet::canopen {

namespace {

constexpr std::uint32_t kProducerBit = 0x40000000;
constexpr std::uint32_t kFrameBit = 0x20000000;
constexpr std::uint32_t kExtendedIdMask = 0x1FFFFFFF;
constexpr std::uint32_t kStandardIdMask = 0x7FF;

// 11-bit identifiers that CiA 301 reserves for NMT, SYNC/EMCY defaults, SDO, heartbeat and LSS
// (CANopenNode `CO_IS_RESTRICTED_CAN_ID`, facts §1).
bool IsRestrictedCanId(std::uint32_t id) {
  return id <= 0x7F || (id >= 0x101 && id <= 0x180) || (id >= 0x581 && id <= 0x5FF) ||
         (id >= 0x601 && id <= 0x67F) || (id >= 0x6E0 && id <= 0x6FF) || id >= 0x701;
}

void AddU32(ObjectDictionary& od, std::uint16_t index, std::string name, std::uint32_t value) {
  od.AddVar(index, std::move(name), DataType::kUnsigned32, Access::kRw, EncodeLe<std::uint32_t>(value));
}

}  // namespace

SyncCobId SyncCobId::Decode(std::uint32_t raw) {
  SyncCobId id;
  id.producer = (raw & kProducerBit) != 0;
  id.extended = (raw & kFrameBit) != 0;
  id.can_id = raw & (id.extended ? kExtendedIdMask : kStandardIdMask);
  return id;
}

SdoAbort CheckSyncCobIdWrite(std::uint32_t current, std::uint32_t requested) {
  SyncCobId now = SyncCobId::Decode(current);
  SyncCobId next = SyncCobId::Decode(requested);
  if (!next.extended && (requested & (kExtendedIdMask & ~kStandardIdMask)) != 0)
    return SdoAbort::kInvalidValue;
  if (!next.extended && IsRestrictedCanId(next.can_id)) return SdoAbort::kInvalidValue;
  if (now.producer && next.producer && (now.can_id != next.can_id || now.extended != next.extended)) {
    return SdoAbort::kInvalidValue;
  }
  return SdoAbort::kNone;
}

SdoAbort CheckSyncCounterOverflowWrite(std::uint8_t requested, std::uint32_t period_us) {
  if (requested == 1 || requested > 240) return SdoAbort::kInvalidValue;
  if (period_us != 0) return SdoAbort::kDeviceState;
  return SdoAbort::kNone;
}

void AddSyncObjects(ObjectDictionary& od, bool with_producer_objects) {
  AddU32(od, kCobIdSyncIndex, "COB-ID SYNC message", kDefaultSyncCobId);
  if (with_producer_objects) AddU32(od, kCommunicationCyclePeriodIndex, "Communication cycle period", 0);
  AddU32(od, kSyncWindowLengthIndex, "Synchronous window length", 0);
  od.AddVar(kSyncCounterOverflowIndex, "Synchronous counter overflow value", DataType::kUnsigned8,
            Access::kRw, {0});
}

}  // namespace canfleet::canopen
