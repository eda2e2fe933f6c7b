#pragma once
/// @file A classical CAN frame as a value type (no heap), shared by every layer.

#include <array>
#include <cstdint>
#include <span>
#include <string>

namespace canfleet {

/// One classical CAN 2.0 frame. 16 bytes, trivially copyable, so a batch of frames is one memcpy.
struct CanFrame {
  static constexpr std::uint32_t kMaxStandardId = 0x7FF;
  static constexpr std::uint32_t kMaxExtendedId = 0x1FFFFFFF;

  enum Flag : std::uint8_t {
    kExtended = 0x01,  ///< 29-bit identifier (CAN 2.0B)
    kRemote = 0x02,    ///< remote transmission request: no data, DLC still meaningful
    kError = 0x04,     ///< error frame (as seen on the wire after a corrupted transfer)
  };

  std::uint32_t id = 0;  ///< 11- or 29-bit identifier, without flag bits
  std::uint8_t dlc = 0;  ///< 0..8
  std::uint8_t flags = 0;
  std::array<std::uint8_t, 8> data{};

  bool extended() const { return (flags & kExtended) != 0; }
  bool remote() const { return (flags & kRemote) != 0; }
  bool error() const { return (flags & kError) != 0; }
  std::span<const std::uint8_t> payload() const { return {data.data(), remote() ? 0u : dlc}; }

  /// True when the identifier fits its format and the DLC is 0..8.
  bool valid() const { return dlc <= 8 && id <= (extended() ? kMaxExtendedId : kMaxStandardId); }

  /// A standard-ID data frame with the given bytes (at most 8 are used).
  static CanFrame Data(std::uint32_t id, std::span<const std::uint8_t> bytes);
  static CanFrame Data(std::uint32_t id, std::initializer_list<std::uint8_t> bytes);
  static CanFrame Remote(std::uint32_t id, std::uint8_t dlc);

  friend bool operator==(const CanFrame&, const CanFrame&);
};

/// candump's compact form: "123#DEADBEEF", "12345678#01", "123#R", "123#R2".
std::string ToCandump(const CanFrame& frame);

static_assert(sizeof(CanFrame) == 16);

}  // namespace canfleet
