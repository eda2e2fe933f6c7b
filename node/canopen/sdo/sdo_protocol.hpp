#pragma once
/// @file The SDO wire format (CiA 301 v4.2 §7.2.4.3): command specifiers, the bits of byte 0, and one
/// encoder per frame of the protocol, each documented with its byte layout. Server and client both
/// build their frames here, so a layout is written down once.
///
/// Every SDO frame has DLC 8 (CiA 301 §7.2.4.3.1); multi-byte fields are little-endian.
/// Notation of byte 0 (as in CiA 301 and CANopenNode's `CO_SDO_state_t` docs):
///   ccs/scs  client/server command specifier, bits 7..5
///   e        expedited transfer                      s  size indicated
///   n        number of bytes that do *not* hold data  t  toggle bit (0 in the first segment)
///   c        1 = last segment                         cc/sc  client/server CRC support
///   seqno    block segment sequence number 1..127
///   cs       block sub-command: 0 initiate, 1 end, 2 acknowledge, 3 start upload
///
/// Clauses of CiA 301 v4.2 §7.2.4.3 cited in this module: .1 general, .3 download initiate, .4 download
/// segment, .6 upload initiate, .7 upload segment, .9 block download initiate, .10 download sub-block,
/// .11 block download end, .13 block upload initiate, .14 upload sub-block, .15 block upload end,
/// .16 block CRC, .17 abort transfer (table 22, the abort codes).

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "node/canopen/od/abort_code.hpp"

namespace canfleet::canopen::sdo {

/// The eight data bytes of one SDO frame.
using Payload = std::array<std::uint8_t, 8>;

/// Predefined connection set (CiA 301 §7.3.5, table 43): client→server 600h+node-ID,
/// server→client 580h+node-ID.
inline constexpr std::uint32_t kRequestCobIdBase = 0x600;
inline constexpr std::uint32_t kResponseCobIdBase = 0x580;

/// Client command specifier: bits 7..5 of byte 0 of a client→server frame.
enum class ClientCommand : std::uint8_t {
  kDownloadSegment = 0,   ///< 000t nnnc
  kInitiateDownload = 1,  ///< 001x nnes
  kInitiateUpload = 2,    ///< 010x xxxx
  kUploadSegment = 3,     ///< 011t xxxx
  kAbort = 4,             ///< 1000 0000
  kBlockUpload = 5,       ///< 101x xccs
  kBlockDownload = 6,     ///< 110x xccs (initiate) / 110n nnxs (end)
  kInvalid = 7,
};

/// Server command specifier: bits 7..5 of byte 0 of a server→client frame.
enum class ServerCommand : std::uint8_t {
  kUploadSegment = 0,     ///< 000t nnnc
  kDownloadSegment = 1,   ///< 001t xxxx
  kInitiateUpload = 2,    ///< 010x nnes
  kInitiateDownload = 3,  ///< 0110 0000
  kAbort = 4,             ///< 1000 0000
  kBlockDownload = 5,     ///< 101x xscs
  kBlockUpload = 6,       ///< 110x xscs
  kInvalid = 7,
};

/// Block sub-command (CiA 301 §7.2.4.3.8–15): bits 1..0 of byte 0 (block download client frames
/// only use bit 0).
enum class BlockSubcommand : std::uint8_t { kInitiate = 0, kEnd = 1, kAck = 2, kStartUpload = 3 };

inline constexpr ClientCommand ClientCommandOf(std::uint8_t byte0) {
  return static_cast<ClientCommand>(byte0 >> 5);
}
inline constexpr ServerCommand ServerCommandOf(std::uint8_t byte0) {
  return static_cast<ServerCommand>(byte0 >> 5);
}
inline constexpr BlockSubcommand BlockSubcommandOf(std::uint8_t byte0) {
  return static_cast<BlockSubcommand>(byte0 & 0x03);
}

inline constexpr std::uint8_t kSizeIndicated = 0x01;  ///< s, initiate frames
inline constexpr std::uint8_t kExpedited = 0x02;      ///< e, initiate frames
inline constexpr std::uint8_t kToggle = 0x10;         ///< t, segment frames
inline constexpr std::uint8_t kLastSegment = 0x01;    ///< c, segment frames
inline constexpr std::uint8_t kBlockCrc = 0x04;       ///< cc/sc, block initiate frames
inline constexpr std::uint8_t kBlockSize = 0x02;      ///< s, block initiate frames
inline constexpr std::uint8_t kBlockLast = 0x80;      ///< c, block segments
inline constexpr std::uint8_t kSeqnoMask = 0x7F;      ///< seqno, block segments
inline constexpr std::uint8_t kAbortCommand = 0x80;

inline constexpr std::size_t kSegmentBytes = 7;     ///< data bytes in a (block) segment
inline constexpr std::uint8_t kMaxBlockSize = 127;  ///< CiA 301 §7.2.4.3.9: 0 < blksize < 128

/// n of an expedited initiate (bits 3..2): bytes 4..7 that do not hold data.
inline constexpr std::size_t ExpeditedSize(std::uint8_t byte0) {
  return 4u - ((byte0 >> 2) & 0x03u);
}
/// n of a segment (bits 3..1): bytes 1..7 that do not hold data.
inline constexpr std::size_t SegmentSize(std::uint8_t byte0) {
  return 7u - ((byte0 >> 1) & 0x07u);
}
/// n of a block end frame (bits 4..2): bytes of the last segment that do not hold data.
inline constexpr std::size_t BlockEndUnused(std::uint8_t byte0) {
  return (byte0 >> 2) & 0x07u;
}

// ---- field access ----------------------------------------------------------------------------

inline constexpr std::uint16_t IndexOf(const Payload& p) {
  return static_cast<std::uint16_t>(p[1] | (p[2] << 8));
}
inline constexpr std::uint8_t SubIndexOf(const Payload& p) {
  return p[3];
}
inline constexpr std::uint32_t U32At(const Payload& p, std::size_t at) {
  return static_cast<std::uint32_t>(p[at]) | static_cast<std::uint32_t>(p[at + 1]) << 8 |
         static_cast<std::uint32_t>(p[at + 2]) << 16 | static_cast<std::uint32_t>(p[at + 3]) << 24;
}
inline constexpr std::uint16_t U16At(const Payload& p, std::size_t at) {
  return static_cast<std::uint16_t>(p[at] | (p[at + 1] << 8));
}
/// The abort code of an abort frame (bytes 4..7).
inline constexpr SdoAbort AbortCodeOf(const Payload& p) {
  return static_cast<SdoAbort>(U32At(p, 4));
}

// ---- encoders ---------------------------------------------------------------------------------

namespace detail {
inline constexpr Payload WithMultiplexer(std::uint8_t byte0, std::uint16_t index, std::uint8_t sub_index) {
  return Payload{
      byte0, static_cast<std::uint8_t>(index), static_cast<std::uint8_t>(index >> 8), sub_index, 0, 0, 0, 0};
}
inline constexpr void PutU32(Payload& p, std::size_t at, std::uint32_t v) {
  for (std::size_t i = 0; i < 4; ++i)
    p[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}
inline void PutData(Payload& p, std::size_t at, std::span<const std::uint8_t> data) {
  std::copy_n(data.begin(), std::min(data.size(), p.size() - at),
              p.begin() + static_cast<std::ptrdiff_t>(at));
}
}  // namespace detail

/// Abort transfer (CiA 301 §7.2.4.3.17), both directions:
/// `80 | idx lo | idx hi | sub | code (LE32)`.
inline constexpr Payload AbortTransfer(std::uint16_t index, std::uint8_t sub_index, SdoAbort code) {
  Payload p = detail::WithMultiplexer(kAbortCommand, index, sub_index);
  detail::PutU32(p, 4, static_cast<std::uint32_t>(code));
  return p;
}

/// Initiate SDO download request, expedited with size (§7.2.4.3.3), 1..4 bytes:
/// `001x nn11 | idx | sub | d0 d1 d2 d3` (23h/27h/2Bh/2Fh for 4/3/2/1 bytes).
inline Payload InitiateDownloadExpedited(std::uint16_t index, std::uint8_t sub_index,
                                         std::span<const std::uint8_t> data) {
  const auto n = static_cast<std::uint8_t>(4 - std::min<std::size_t>(data.size(), 4));
  Payload p = detail::WithMultiplexer(static_cast<std::uint8_t>(0x23 | n << 2), index, sub_index);
  detail::PutData(p, 4, data.first(std::min<std::size_t>(data.size(), 4)));
  return p;
}

/// Initiate SDO download request, segmented (§7.2.4.3.3):
/// `0010 0001 | idx | sub | size (LE32)` (21h), or `20h` with bytes 4..7 zero when no size is given.
inline constexpr Payload InitiateDownloadSegmented(std::uint16_t index, std::uint8_t sub_index,
                                                   std::optional<std::uint32_t> size) {
  Payload p = detail::WithMultiplexer(size ? 0x21 : 0x20, index, sub_index);
  if (size) detail::PutU32(p, 4, *size);
  return p;
}

/// Initiate SDO download response (§7.2.4.3.3): `60 | idx | sub | 00 00 00 00`.
inline constexpr Payload InitiateDownloadResponse(std::uint16_t index, std::uint8_t sub_index) {
  return detail::WithMultiplexer(0x60, index, sub_index);
}

/// Download SDO segment request (§7.2.4.3.4): `000t nnnc | seg-data (7 bytes, n unused)`.
/// Upload SDO segment response (§7.2.4.3.7) has the same layout.
inline Payload Segment(bool toggle, std::span<const std::uint8_t> data, bool last) {
  const auto len = std::min(data.size(), kSegmentBytes);
  Payload p{};
  p[0] = static_cast<std::uint8_t>((toggle ? kToggle : 0) | (kSegmentBytes - len) << 1 |
                                   (last ? kLastSegment : 0));
  detail::PutData(p, 1, data.first(len));
  return p;
}

/// Download SDO segment response (§7.2.4.3.4): `001t 0000 | 7 bytes reserved (0)` (20h/30h).
inline constexpr Payload DownloadSegmentResponse(bool toggle) {
  return Payload{static_cast<std::uint8_t>(0x20 | (toggle ? kToggle : 0)), 0, 0, 0, 0, 0, 0, 0};
}

/// Initiate SDO upload request (§7.2.4.3.6): `40 | idx | sub | 00 00 00 00`.
inline constexpr Payload InitiateUploadRequest(std::uint16_t index, std::uint8_t sub_index) {
  return detail::WithMultiplexer(0x40, index, sub_index);
}

/// Initiate SDO upload response, expedited with size (§7.2.4.3.6), 1..4 bytes:
/// `010x nn11 | idx | sub | d0 d1 d2 d3` (43h/47h/4Bh/4Fh for 4/3/2/1 bytes).
inline Payload InitiateUploadExpedited(std::uint16_t index, std::uint8_t sub_index,
                                       std::span<const std::uint8_t> data) {
  const auto n = static_cast<std::uint8_t>(4 - std::min<std::size_t>(data.size(), 4));
  Payload p = detail::WithMultiplexer(static_cast<std::uint8_t>(0x43 | n << 2), index, sub_index);
  detail::PutData(p, 4, data.first(std::min<std::size_t>(data.size(), 4)));
  return p;
}

/// Initiate SDO upload response, segmented with size (§7.2.4.3.6): `41 | idx | sub | size (LE32)`.
inline constexpr Payload InitiateUploadSegmented(std::uint16_t index, std::uint8_t sub_index,
                                                 std::uint32_t size) {
  Payload p = detail::WithMultiplexer(0x41, index, sub_index);
  detail::PutU32(p, 4, size);
  return p;
}

/// Upload SDO segment request (§7.2.4.3.7): `011t 0000 | 7 bytes reserved (0)` (60h/70h).
inline constexpr Payload UploadSegmentRequest(bool toggle) {
  return Payload{static_cast<std::uint8_t>(0x60 | (toggle ? kToggle : 0)), 0, 0, 0, 0, 0, 0, 0};
}

/// Initiate block download request (§7.2.4.3.9): `110x 0cs0 | idx | sub | size (LE32, 0 if s=0)`
/// (C0h/C2h/C4h/C6h).
inline constexpr Payload BlockDownloadInitiate(std::uint16_t index, std::uint8_t sub_index, bool crc,
                                               std::optional<std::uint32_t> size) {
  Payload p = detail::WithMultiplexer(
      static_cast<std::uint8_t>(0xC0 | (crc ? kBlockCrc : 0) | (size ? kBlockSize : 0)), index, sub_index);
  if (size) detail::PutU32(p, 4, *size);
  return p;
}

/// Initiate block download response (§7.2.4.3.9): `1010 0s00 | idx | sub | blksize | 00 00 00`
/// (A0h, A4h with server CRC support).
inline constexpr Payload BlockDownloadInitiateResponse(std::uint16_t index, std::uint8_t sub_index, bool crc,
                                                       std::uint8_t blksize) {
  Payload p =
      detail::WithMultiplexer(static_cast<std::uint8_t>(0xA0 | (crc ? kBlockCrc : 0)), index, sub_index);
  p[4] = blksize;
  return p;
}

/// Block segment, download (§7.2.4.3.10) and upload (§7.2.4.3.14): `c seqno(7 bits) | seg-data (7)`.
inline Payload BlockSegment(std::uint8_t seqno, bool last, std::span<const std::uint8_t> data) {
  Payload p{};
  p[0] = static_cast<std::uint8_t>((last ? kBlockLast : 0) | (seqno & kSeqnoMask));
  detail::PutData(p, 1, data.first(std::min(data.size(), kSegmentBytes)));
  return p;
}

/// Block acknowledgement (§7.2.4.3.10 server→client, §7.2.4.3.14 client→server; both A2h):
/// `1010 0010 | ackseq | blksize | 00 00 00 00 00`. ackseq = last segment received in order
/// (0 = none: resend the whole sub-block); blksize = segments in the next sub-block.
inline constexpr Payload BlockAck(std::uint8_t ackseq, std::uint8_t blksize) {
  return Payload{0xA2, ackseq, blksize, 0, 0, 0, 0, 0};
}

/// End block download request (§7.2.4.3.11): `110n nn01 | crc (LE16) | 5 bytes reserved`.
/// End block upload request (§7.2.4.3.15, server→client) has the same layout.
inline constexpr Payload BlockEnd(std::size_t unused, std::uint16_t crc) {
  return Payload{static_cast<std::uint8_t>(0xC1 | (unused & 0x07) << 2),
                 static_cast<std::uint8_t>(crc),
                 static_cast<std::uint8_t>(crc >> 8),
                 0,
                 0,
                 0,
                 0,
                 0};
}

/// End block download response (§7.2.4.3.11, server→client) and end block upload response
/// (§7.2.4.3.15, client→server): `1010 0001 | 7 bytes reserved` (A1h).
inline constexpr Payload BlockEndResponse() {
  return Payload{0xA1, 0, 0, 0, 0, 0, 0, 0};
}

/// Initiate block upload request (§7.2.4.3.13): `1010 0c00 | idx | sub | blksize | pst | 00 00`
/// (A0h/A4h). pst = protocol switch threshold in bytes (0 = no switch).
inline constexpr Payload BlockUploadInitiate(std::uint16_t index, std::uint8_t sub_index, bool crc,
                                             std::uint8_t blksize, std::uint8_t pst) {
  Payload p =
      detail::WithMultiplexer(static_cast<std::uint8_t>(0xA0 | (crc ? kBlockCrc : 0)), index, sub_index);
  p[4] = blksize;
  p[5] = pst;
  return p;
}

/// Initiate block upload response (§7.2.4.3.13): `1100 0s10 | idx | sub | size (LE32)` (C2h/C6h).
inline constexpr Payload BlockUploadInitiateResponse(std::uint16_t index, std::uint8_t sub_index, bool crc,
                                                     std::uint32_t size) {
  Payload p = detail::WithMultiplexer(static_cast<std::uint8_t>(0xC0 | (crc ? kBlockCrc : 0) | kBlockSize),
                                      index, sub_index);
  detail::PutU32(p, 4, size);
  return p;
}

/// Start block upload (part of §7.2.4.3.13, client→server): `1010 0011 | 7 bytes reserved` (A3h).
inline constexpr Payload BlockUploadStart() {
  return Payload{0xA3, 0, 0, 0, 0, 0, 0, 0};
}

/// Bytes of the last segment that hold no data when `total` bytes travel in 7-byte segments
/// (an empty transfer still sends one segment, with no data).
inline constexpr std::size_t UnusedInLastSegment(std::size_t total) {
  return total == 0 ? kSegmentBytes : (kSegmentBytes - total % kSegmentBytes) % kSegmentBytes;
}

}  // namespace canfleet::canopen::sdo
