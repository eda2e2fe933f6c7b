#pragma once
/// @file One error condition as the EMCY producer records it: the EMCY code, the manufacturer part
/// of its 1003h entry, the 1001h bits it sets and the manufacturer bytes of its EMCY frame.

#include <array>
#include <cstdint>

namespace canfleet::canopen {

/// 1001h error register bits (CiA 301 v4.2 §7.5.2.2, table 47). Bit 6 is reserved and kept 0.
inline constexpr std::uint8_t kErrorRegisterGeneric = 0x01;
inline constexpr std::uint8_t kErrorRegisterCurrent = 0x02;
inline constexpr std::uint8_t kErrorRegisterVoltage = 0x04;
inline constexpr std::uint8_t kErrorRegisterTemperature = 0x08;
// kErrorRegisterCommunication (0x10) lives in stack/error_policy.hpp.
inline constexpr std::uint8_t kErrorRegisterDeviceProfile = 0x20;
inline constexpr std::uint8_t kErrorRegisterManufacturer = 0x80;

/// An error condition. Two entries are the same error when (code, info) are equal: raising it
/// again while active changes nothing, clearing it takes both.
struct ErrorEntry {
  /// EMCY error code (CiA 301 §7.2.7.1 table 21); the low 16 bits of the 1003h entry. 0000h is
  /// "error reset / no error" and cannot be raised.
  std::uint16_t code = 0;
  /// Manufacturer-specific part of the 1003h entry (its high 16 bits, CiA 301 §7.5.2.3), e.g.
  /// (description << 8) | channel on the Quad controller.
  std::uint16_t info = 0;
  /// 1001h bits this error sets while active. Bit 0 (generic) is set while any error is active.
  std::uint8_t register_bits = kErrorRegisterGeneric;
  /// Manufacturer-specific error field of the EMCY frame (bytes 3-7).
  std::array<std::uint8_t, 5> msef{};

  /// The 32-bit 1003h entry: info in bits 31-16, code in bits 15-0.
  std::uint32_t HistoryValue() const { return (std::uint32_t{info} << 16) | code; }
};

}  // namespace canfleet::canopen
