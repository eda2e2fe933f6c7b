#pragma once
/// @file The fixed 24-byte record a frame travels in (canfleet_wire.proto, FrameBatch):
///
///   0..7   int64   time_ns   bus time in ns; node -> broker: 0
///   8..11  uint32  id        11- or 29-bit identifier, no flag bits
///   12     uint8   dlc       0..8
///   13     uint8   flags     CanFrame::Flag bits (0x01 extended, 0x02 remote, 0x04 error)
///   14..15         reserved  0
///   16..23 uint8[8] data     bytes beyond the DLC (all, for a remote frame): written as 0,
///                            ignored when read
///
/// All integers little-endian.

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>

#include "bus/bus_port.hpp"
#include "bus/can_frame.hpp"

namespace canfleet::wire {

inline constexpr std::size_t kFrameRecordSize = 24;

/// A frame with the bus time it carries.
struct StampedFrame {
  CanFrame frame;
  BusTime time{};
};

/// Writes one record at `out` (kFrameRecordSize bytes). Bytes beyond the DLC are written as 0.
inline void EncodeRecord(const CanFrame& frame, BusTime time, std::uint8_t* out) {
  const std::int64_t ns = time.count();
  if constexpr (std::endian::native == std::endian::little) {
    std::memcpy(out, &ns, 8);
    std::memcpy(out + 8, &frame.id, 4);
  } else {
    for (std::size_t i = 0; i < 8; ++i)
      out[i] = static_cast<std::uint8_t>(static_cast<std::uint64_t>(ns) >> (8 * i));
    for (std::size_t i = 0; i < 4; ++i)
      out[8 + i] = static_cast<std::uint8_t>(frame.id >> (8 * i));
  }
  out[12] = frame.dlc;
  out[13] = frame.flags;
  out[14] = 0;
  out[15] = 0;
  // Whole 8 bytes, then zero the unused tail: cheaper than a variable-length copy.
  std::memcpy(out + 16, frame.data.data(), 8);
  const std::size_t used = frame.remote() ? 0 : std::min<std::size_t>(frame.dlc, 8);
  std::memset(out + 16 + used, 0, 8 - used);
}

/// Checks one record; on failure returns false and says why in `error`.
bool ValidateRecord(const std::uint8_t* record, std::string& error);

/// Reads one record that ValidateRecord accepted. Inline: it runs once per frame and receiver.
inline StampedFrame DecodeRecord(const std::uint8_t* record) {
  StampedFrame out;
  std::int64_t ns = 0;
  if constexpr (std::endian::native == std::endian::little) {
    std::memcpy(&ns, record, 8);
    std::memcpy(&out.frame.id, record + 8, 4);
  } else {
    for (std::size_t i = 0; i < 8; ++i)
      ns |= static_cast<std::int64_t>(static_cast<std::uint64_t>(record[i]) << (8 * i));
    out.frame.id = 0;
    for (std::size_t i = 0; i < 4; ++i)
      out.frame.id |= static_cast<std::uint32_t>(record[8 + i]) << (8 * i);
  }
  out.time = BusTime(ns);
  out.frame.dlc = record[12];
  out.frame.flags = record[13];
  std::memcpy(out.frame.data.data(), record + 16, 8);
  return out;
}

/// A validated run of records (a view: the bytes belong to someone else).
class FrameRecords {
 public:
  FrameRecords() = default;
  /// `bytes` must be whole records, each accepted by ValidateRecord.
  explicit FrameRecords(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}

  std::size_t size() const { return bytes_.size() / kFrameRecordSize; }
  bool empty() const { return bytes_.empty(); }
  StampedFrame operator[](std::size_t i) const { return DecodeRecord(bytes_.data() + i * kFrameRecordSize); }
  std::span<const std::uint8_t> bytes() const { return bytes_; }

 private:
  std::span<const std::uint8_t> bytes_;
};

/// Validates a records field: whole records, each valid. Error names the first bad record.
bool ValidateRecords(std::span<const std::uint8_t> bytes, std::string& error);

}  // namespace canfleet::wire
