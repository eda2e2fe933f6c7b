#include "node/devices/od_ref.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <stdexcept>

namespace canfleet::devices {

using canopen::DataType;

std::string FormatEntry(std::uint16_t index, std::uint8_t sub_index) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%04Xh.%u", static_cast<unsigned>(index), static_cast<unsigned>(sub_index));
  return buf;
}

OdRef::OdRef(canopen::ObjectDictionary& od, std::uint16_t index, std::uint8_t sub_index) : od_(&od) {
  sub_ = od.Find(index, sub_index);
  if (!sub_)
    throw std::logic_error("object " + FormatEntry(index, sub_index) + " missing from the dictionary");
  auto size = canopen::FixedSize(sub_->type);
  if (!size || *size > 8 || canopen::IsReal(sub_->type))
    throw std::logic_error("object " + FormatEntry(index, sub_index) + " is not an integer");
}

std::int64_t OdRef::Get() const {
  if (canopen::IsSigned(sub_->type)) return canopen::DecodeSignedLe(sub_->value);
  return static_cast<std::int64_t>(canopen::DecodeUnsignedLe(sub_->value));
}

bool OdRef::Set(std::int64_t value) const {
  const std::size_t size = canopen::FixedSize(sub_->type).value_or(0);
  std::array<std::uint8_t, 8> bytes{};
  auto raw = static_cast<std::uint64_t>(value);
  for (std::size_t i = 0; i < size; ++i)
    bytes[i] = static_cast<std::uint8_t>(raw >> (8 * i));
  std::span<const std::uint8_t> data(bytes.data(), size);
  if (std::equal(data.begin(), data.end(), sub_->value.begin(), sub_->value.end())) return false;
  od_->Write(*sub_, data, canopen::Origin::kDevice);
  return true;
}

}  // namespace canfleet::devices
