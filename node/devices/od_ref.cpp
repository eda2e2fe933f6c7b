#include "node/devices/od_ref.hpp"

#include <algorithm>
#include <array>
#include <cmath>
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
  if (!size || *size > 8 ||
      !(canopen::IsSigned(sub_->type) || canopen::IsUnsigned(sub_->type) || canopen::IsReal(sub_->type)))
    throw std::logic_error("object " + FormatEntry(index, sub_index) + " is not a number");
}

std::int64_t OdRef::Get() const {
  if (IsReal()) {
    const double v = std::round(GetNumber());
    if (std::isnan(v)) return 0;
    constexpr double kLimit = 9.2e18;  // inside the int64 range, and exactly representable
    return static_cast<std::int64_t>(std::clamp(v, -kLimit, kLimit));
  }
  if (canopen::IsSigned(sub_->type)) return canopen::DecodeSignedLe(sub_->value);
  return static_cast<std::int64_t>(canopen::DecodeUnsignedLe(sub_->value));
}

double OdRef::GetNumber() const {
  return canopen::DecodeAsDouble(sub_->type, sub_->value);
}

bool OdRef::Set(std::int64_t value) const {
  if (IsReal()) return SetNumber(static_cast<double>(value));
  const std::size_t size = canopen::FixedSize(sub_->type).value_or(0);
  std::array<std::uint8_t, 8> bytes{};
  auto raw = static_cast<std::uint64_t>(value);
  for (std::size_t i = 0; i < size; ++i)
    bytes[i] = static_cast<std::uint8_t>(raw >> (8 * i));
  return WriteBytes(std::span<const std::uint8_t>(bytes.data(), size));
}

bool OdRef::SetNumber(double value) const {
  if (std::isnan(value)) return false;
  if (sub_->type == DataType::kReal32) return WriteBytes(canopen::EncodeLe(static_cast<float>(value)));
  if (sub_->type == DataType::kReal64) return WriteBytes(canopen::EncodeLe(value));
  // An integer type: the nearest integer, saturated to the type's range (a block's percent
  // result never wraps around into a nonsense command).
  const std::size_t bits = 8 * canopen::FixedSize(sub_->type).value_or(8);
  const bool is_signed = canopen::IsSigned(sub_->type);
  const double lowest = is_signed ? -std::ldexp(1.0, static_cast<int>(bits) - 1) : 0.0;
  const double highest = is_signed ? std::ldexp(1.0, static_cast<int>(bits) - 1) - 1
                                   : std::ldexp(1.0, static_cast<int>(bits)) - 1;
  const double rounded = std::clamp(std::round(value), lowest, std::min(highest, 9.2e18));
  if (sub_->type == DataType::kBoolean) return Set(rounded != 0 ? 1 : 0);
  return Set(is_signed ? static_cast<std::int64_t>(rounded)
                       : static_cast<std::int64_t>(static_cast<std::uint64_t>(rounded)));
}

bool OdRef::WriteBytes(std::span<const std::uint8_t> data) const {
  if (std::equal(data.begin(), data.end(), sub_->value.begin(), sub_->value.end())) return false;
  od_->Write(*sub_, data, canopen::Origin::kDevice);
  return true;
}

}  // namespace canfleet::devices
