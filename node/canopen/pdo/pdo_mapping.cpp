#include "node/canopen/pdo/pdo_mapping.hpp"

#include <algorithm>
#include <optional>

namespace canfleet::canopen {

namespace {

constexpr std::uint32_t kMaxPdoBits = 64;

constexpr std::uint64_t Mask(std::uint32_t bits) {
  return bits >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << bits) - 1;
}

// The data types whose index may appear in a dummy entry (CiA 301 §7.4.7.1, table 44).
std::optional<DataType> DummyType(std::uint16_t index) {
  if (index == 0 || index > 0x1F) return std::nullopt;
  auto type = static_cast<DataType>(index);
  if (!FixedSize(type)) return std::nullopt;
  return type;
}

SdoAbort CheckLength(MappedObject& out, DataType type, std::uint8_t length) {
  const auto size = FixedSize(type);
  if (!size || length == 0 || length > 8 * *size) return SdoAbort::kNotMappable;
  out.length = length;
  out.size = static_cast<std::uint8_t>(*size);
  out.is_signed = IsSigned(type);
  return SdoAbort::kNone;
}

}  // namespace

bool PdoMapping::Maps(const SubObject& sub) const {
  return std::any_of(entries_.begin(), entries_.end(), [&](const MappedObject& e) { return e.sub == &sub; });
}

void PdoMapping::Clear() {
  entries_.clear();
  bits_ = 0;
}

bool PdoMapping::Append(MappedObject entry) {
  if (bits_ + entry.length > kMaxPdoBits) return false;
  entry.offset = static_cast<std::uint8_t>(bits_);
  bits_ += entry.length;
  entries_.push_back(entry);
  return true;
}

void PdoMapping::Pack(std::array<std::uint8_t, 8>& data) const {
  std::uint64_t frame = 0;
  for (const auto& e : entries_) {
    if (!e.sub || e.length == 0) continue;
    for (const auto& hook : e.sub->read_hooks())
      (void)hook(*e.sub, Origin::kPdo);
    frame |= (DecodeUnsignedLe(e.sub->value) & Mask(e.length)) << e.offset;
  }
  for (std::size_t i = 0; i < data.size(); ++i)
    data[i] = static_cast<std::uint8_t>(frame >> (8 * i));
}

void PdoMapping::Unpack(ObjectDictionary& od, std::span<const std::uint8_t> data) const {
  const std::uint64_t frame = DecodeUnsignedLe(data.first(std::min<std::size_t>(data.size(), 8)));
  std::array<std::uint8_t, 8> bytes{};
  for (const auto& e : entries_) {
    if (!e.sub || e.length == 0) continue;
    std::uint64_t value = (frame >> e.offset) & Mask(e.length);
    if (e.is_signed && e.length < 64 && ((value >> (e.length - 1)) & 1) != 0) value |= ~Mask(e.length);
    for (std::size_t i = 0; i < e.size; ++i)
      bytes[i] = static_cast<std::uint8_t>(value >> (8 * i));
    (void)od.Write(*e.sub, std::span<const std::uint8_t>(bytes.data(), e.size), Origin::kPdo);
  }
}

SdoAbort CheckMappingEntry(ObjectDictionary& od, PdoDirection direction, std::uint32_t entry,
                           MappedObject& out) {
  out = MappedObject{};
  if (entry == 0) return SdoAbort::kNone;
  const auto index = static_cast<std::uint16_t>(entry >> 16);
  const auto sub_index = static_cast<std::uint8_t>(entry >> 8);
  const auto length = static_cast<std::uint8_t>(entry);
  if (sub_index == 0) {
    if (auto dummy = DummyType(index)) {
      if (direction == PdoDirection::kTransmit) return SdoAbort::kNotMappable;
      return CheckLength(out, *dummy, length);
    }
  }
  SubObject* sub = nullptr;
  if (auto rc = od.Lookup(index, sub_index, sub); rc != SdoAbort::kNone) return rc;
  const bool accessible =
      direction == PdoDirection::kReceive ? IsWritable(sub->access) : IsReadable(sub->access);
  if (!sub->pdo_mappable || !accessible) return SdoAbort::kNotMappable;
  if (auto rc = CheckLength(out, sub->type, length); rc != SdoAbort::kNone) return rc;
  out.sub = sub;
  return SdoAbort::kNone;
}

SdoAbort ResolveMapping(ObjectDictionary& od, PdoDirection direction, const Object& record,
                        std::uint8_t count, PdoMapping& out) {
  out.Clear();
  // sub0 above what the record holds is a bad value whatever the entries say.
  if (count > kMaxMappingEntries) return SdoAbort::kInvalidValue;
  for (std::uint8_t i = 1; i <= count; ++i) {
    if (!record.subs.contains(i)) return SdoAbort::kInvalidValue;
  }
  for (std::uint8_t i = 1; i <= count; ++i) {
    auto it = record.subs.find(i);
    MappedObject entry;
    auto rc = CheckMappingEntry(od, direction, static_cast<std::uint32_t>(DecodeUnsignedLe(it->second.value)),
                                entry);
    if (rc != SdoAbort::kNone) return rc;
    if (!out.Append(entry)) return SdoAbort::kPdoLengthExceeded;
  }
  return SdoAbort::kNone;
}

}  // namespace canfleet::canopen
