#pragma once
/// @file pcap files with LINKTYPE_CAN_SOCKETCAN (227), which Wireshark/tshark decode as CAN and
/// hand to their CANopen dissector. Written by hand (no libpcap), little-endian headers.
///
/// Global header (24 bytes):
///
///     magic 0xA1B2C3D4 (µs timestamps) | version 2.4 | thiszone 0 | sigfigs 0 | snaplen | 227
///
/// Each record: a 16-byte record header (ts_sec, ts_usec, incl_len, orig_len) and 16 bytes of
/// frame, laid out as Linux's `struct can_frame` (CAN_MTU) but with the identifier in network
/// byte order, as https://www.tcpdump.org/linktypes/LINKTYPE_CAN_SOCKETCAN.html specifies:
///
///     byte 0..3  CAN id + EFF/RTR/ERR flags, big-endian (see bus/capture/socketcan_layout.hpp)
///     byte 4     payload length (DLC 0..8; the requested DLC of a remote frame)
///     byte 5     FD flags: 0 (padding in a classical frame)
///     byte 6..7  reserved: 0 (byte 7 is len8_dlc, unused here)
///     byte 8..15 data, zero beyond the length

#include <array>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "bus/capture/capture_file.hpp"
#include "bus/capture/capture_writer.hpp"

namespace canfleet::capture {

inline constexpr std::uint32_t kLinktypeCanSocketcan = 227;
inline constexpr std::uint32_t kPcapMagicMicroseconds = 0xA1B2C3D4;
inline constexpr std::uint32_t kPcapSnaplen = 65535;
inline constexpr std::size_t kPcapGlobalHeaderSize = 24;
inline constexpr std::size_t kPcapRecordHeaderSize = 16;
inline constexpr std::size_t kSocketCanFrameSize = 16;  ///< CAN_MTU
inline constexpr std::size_t kPcapRecordSize = kPcapRecordHeaderSize + kSocketCanFrameSize;

std::array<std::uint8_t, kPcapGlobalHeaderSize> PcapGlobalHeader();

/// One record (header + frame), 32 bytes. Times before the epoch are written as 0.
std::array<std::uint8_t, kPcapRecordSize> PcapRecord(const CanFrame& frame, WallTime time);

class PcapWriter final : public CaptureWriter {
 public:
  /// Creates the file and writes the global header. Throws std::system_error when it cannot.
  explicit PcapWriter(const std::filesystem::path& path);

  void Write(const CanFrame& frame, WallTime time) override;
  void Flush() override { file_.Flush(); }
  void Close() override { file_.Close(); }
  bool ok() const override { return file_.ok(); }
  const std::string& error() const override { return file_.error(); }

 private:
  CaptureFile file_;
};

}  // namespace canfleet::capture
