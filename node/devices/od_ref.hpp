#pragma once
/// @file A sub-object a function block reads or writes on every tick, resolved once when the block
/// is attached (objects never move once added to a dictionary), read and written as an integer or,
/// for the family's REAL32 objects (constants 5010h, supply 5020h, current-loop gains 2382h...)
/// and for the blocks that compute in percent, as a number.

#include <cstdint>
#include <string>

#include "node/canopen/od/object_dictionary.hpp"

namespace canfleet::devices {

class OdRef {
 public:
  OdRef() = default;
  /// @throws std::logic_error naming index and sub-index when the dictionary lacks the entry or it
  ///         is not a number (an integer of at most 64 bits, BOOLEAN, REAL32 or REAL64): the
  ///         device's EDS does not fit its code, which is found when the node is built (an edge),
  ///         never later.
  OdRef(canopen::ObjectDictionary& od, std::uint16_t index, std::uint8_t sub_index);

  /// The value: signed types sign-extended, unsigned types (and BOOLEAN) zero-extended; a real
  /// rounded to the nearest integer (saturated to the int64 range).
  std::int64_t Get() const;
  /// The value as a number, whatever the type (reals exactly, integers converted).
  double GetNumber() const;
  /// Writes a number: a real type takes it as it is (REAL32 rounded to float); an integer type takes
  /// it rounded to the nearest integer and saturated to the type's range. Returns true if the value
  /// changed. NaN writes nothing.
  bool SetNumber(double value) const;
  bool IsReal() const { return canopen::IsReal(sub_->type); }
  /// Bit `bit` of the value.
  bool Bit(unsigned bit) const { return ((Get() >> bit) & 1) != 0; }
  /// Writes as the device (Origin::kDevice: no access, limit or validator checks; listeners run),
  /// truncated to the type's size (a real type takes the integer as a number). Returns true if the
  /// value changed; an unchanged value is not written, so listeners hear only changes.
  bool Set(std::int64_t value) const;

  canopen::SubObject& sub() const { return *sub_; }
  explicit operator bool() const { return sub_ != nullptr; }

 private:
  bool WriteBytes(std::span<const std::uint8_t> data) const;

  canopen::ObjectDictionary* od_ = nullptr;
  canopen::SubObject* sub_ = nullptr;
};

/// "7330h.1" for messages.
std::string FormatEntry(std::uint16_t index, std::uint8_t sub_index);

}  // namespace canfleet::devices
