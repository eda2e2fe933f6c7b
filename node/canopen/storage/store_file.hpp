#pragma once
/// @file The on-disk format of stored parameters (one file per 1010h group, plus one for the LSS
/// configuration). Pure encoding and decoding: no file system, no object dictionary, so the
/// parser can be fuzzed on its own.
///
/// All numbers little-endian. A file is a 16-byte header followed by the payload:
///
///     offset size  header
///          0    4  magic "CFPS" (43h 46h 50h 53h)
///          4    2  format version (kStoreFormatVersion)
///          6    1  group (StoreGroup)
///          7    1  reserved, 0
///          8    4  payload length in bytes (the file is exactly 16 + length bytes)
///         12    4  CRC-32 (IEEE 802.3, as zlib) of the payload
///
///     payload of a parameter group (comm / application / manufacturer)
///          0    4  vendor-ID (1018h sub 1) of the device that wrote the file
///          4    4  product code (1018h sub 2)
///          8    4  entry count n
///         12       n entries, each:
///                    2  index
///                    1  sub-index
///                    2  data type (CiA 301 §7.4.7.1 index, DataType)
///                    1  flags: bit 0 = value is node-ID relative (add the node-ID when applied)
///                    2  value length in bytes
///                    …  value, encoded as in the object dictionary
///
///     payload of the LSS group
///          0    4  vendor-ID, 4 product code (as above)
///          8    1  node-ID (1..127, or FFh = non-configured)
///          9    1  bit timing index (CiA 301 table, 0..8 without 5)
///
/// The vendor-ID and product code make a file from another device type (a reused state folder)
/// recognisable as foreign.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "node/canopen/od/types.hpp"
#include "node/canopen/od/value.hpp"

namespace canfleet::canopen {

inline constexpr std::uint16_t kStoreFormatVersion = 1;
inline constexpr std::size_t kStoreHeaderSize = 16;
/// Files above this size are refused before they are read into memory.
inline constexpr std::size_t kStoreMaxFileSize = 16 * 1024 * 1024;

/// Which stored area a file holds (header byte 6).
enum class StoreGroup : std::uint8_t {
  kCommunication = 1,  ///< 1010h/1011h sub 2: 1000h–1FFFh
  kApplication = 2,    ///< sub 3: 6000h–9FFFh
  kManufacturer = 3,   ///< sub 4: 2000h–5FFFh
  kLss = 0x10,         ///< CiA 305 store configuration: node-ID and bit timing
};

/// Why a file or an entry was not applied.
enum class StoreProblem : std::uint8_t {
  kIoError,       ///< the file exists but could not be read
  kTooLarge,      ///< larger than kStoreMaxFileSize
  kEmpty,         ///< zero-length file
  kTruncated,     ///< shorter than its header or than header + payload length
  kBadMagic,      ///< not a canfleet store file
  kBadVersion,    ///< written by an unknown format version
  kBadHeader,     ///< reserved header byte not 0
  kBadLength,     ///< longer than header + payload length
  kBadCrc,        ///< payload CRC-32 differs: corrupt
  kForeign,       ///< another group's file, or another device type's (1018h vendor/product)
  kMalformed,     ///< CRC fine but the payload does not parse (or an entry is inconsistent)
  kNoSuchObject,  ///< entry: index/sub-index no longer in the object dictionary
  kTypeMismatch,  ///< entry: data type differs from the object dictionary's
  kSizeMismatch,  ///< entry: length differs from the type's size
  kNotStorable,   ///< entry: object no longer writable, or excluded from storage
  kOutOfRange,    ///< entry: value outside the object's limits
  kOutsideGroup,  ///< entry: index outside the range of the file's group
  kRejected,      ///< entry: the object dictionary refused the write
};

const char* ToString(StoreProblem problem);
const char* ToString(StoreGroup group);

/// One stored sub-object value.
struct StoreEntry {
  std::uint16_t index = 0;
  std::uint8_t sub_index = 0;
  DataType type = DataType::kUnsigned8;
  /// The value has the node-ID subtracted; applying adds the then current node-ID, so COB-IDs
  /// that followed the "$NODEID" default keep following it after a node-ID change.
  bool node_id_relative = false;
  Bytes value;
  friend bool operator==(const StoreEntry&, const StoreEntry&) = default;
};

/// The CiA 305 persistent configuration.
struct LssConfig {
  std::uint8_t node_id = 0xFF;
  std::uint8_t bit_timing_index = 4;
  friend bool operator==(const LssConfig&, const LssConfig&) = default;
};

/// The decoded content of one file.
struct StoreImage {
  StoreGroup group = StoreGroup::kCommunication;
  std::uint32_t vendor_id = 0;
  std::uint32_t product_code = 0;
  std::vector<StoreEntry> entries;  ///< parameter groups
  LssConfig lss;                    ///< kLss only
};

/// Outcome of DecodeStoreFile: an image, or the problem and a detail for the log.
struct DecodeResult {
  std::optional<StoreImage> image;
  StoreProblem problem = StoreProblem::kMalformed;
  std::string detail;
};

/// CRC-32 (IEEE 802.3 polynomial 04C11DB7h reflected, init and final XOR FFFFFFFFh; "123456789"
/// gives CBF43926h). `crc` continues a previous call.
std::uint32_t Crc32(std::span<const std::uint8_t> data, std::uint32_t crc = 0);

/// Encodes a file. Values longer than 65535 bytes cannot be encoded: callers leave them out.
Bytes EncodeStoreFile(const StoreImage& image);

/// Decodes and checks a whole file: size, magic, version, header, length, CRC, group (must be
/// `expected`) and payload structure. Never throws, never reads outside `bytes`.
DecodeResult DecodeStoreFile(std::span<const std::uint8_t> bytes, StoreGroup expected);

}  // namespace canfleet::canopen
