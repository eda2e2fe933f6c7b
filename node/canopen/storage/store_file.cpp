#include "node/canopen/storage/store_file.hpp"

#include <algorithm>
#include <array>
#include <cstdio>

#include "node/canopen/storage/le_writer.hpp"

namespace canfleet::canopen {

namespace {

constexpr std::array<std::uint8_t, 4> kMagic{'C', 'F', 'P', 'S'};
constexpr std::size_t kIdentitySize = 8;
constexpr std::size_t kEntryHeaderSize = 8;  // index 2, sub 1, type 2, flags 1, length 2
constexpr std::uint8_t kFlagNodeIdRelative = 0x01;

constexpr std::array<std::uint32_t, 256> MakeCrcTable() {
  std::array<std::uint32_t, 256> table{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k)
      c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    table[i] = c;
  }
  return table;
}
constexpr auto kCrcTable = MakeCrcTable();

using le::Patch32;
using le::Put16;
using le::Put32;
using le::Put8;

/// Bounds-checked little-endian reader: every Get fails (and keeps failing) instead of reading
/// past the end, so a hostile length can never make the parser overrun.
class Reader {
 public:
  explicit Reader(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
  bool Get8(std::uint8_t& v) {
    return Take(1, [&](auto p) { v = p[0]; });
  }
  bool Get16(std::uint16_t& v) {
    return Take(2, [&](auto p) { v = static_cast<std::uint16_t>(p[0] | p[1] << 8); });
  }
  bool Get32(std::uint32_t& v) {
    return Take(4, [&](auto p) {
      v = static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
          static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
    });
  }
  bool GetBytes(std::size_t n, Bytes& v) {
    return Take(n, [&](auto p) { v.assign(p, p + n); });
  }
  std::size_t Remaining() const { return bytes_.size() - pos_; }

 private:
  template <typename F>
  bool Take(std::size_t n, F&& use) {
    if (n > Remaining()) return false;
    use(bytes_.data() + pos_);
    pos_ += n;
    return true;
  }
  std::span<const std::uint8_t> bytes_;
  std::size_t pos_ = 0;
};

DecodeResult Fail(StoreProblem problem, std::string detail) {
  return {std::nullopt, problem, std::move(detail)};
}

std::string Hex(std::uint32_t v, int digits) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%0*Xh", digits, v);
  return buf;
}

bool ParseEntries(Reader& in, StoreImage& image, std::string& detail) {
  std::uint32_t count = 0;
  if (!in.Get32(count)) {
    detail = "no entry count";
    return false;
  }
  // Each entry takes at least kEntryHeaderSize bytes: a count that cannot fit is a lie, and
  // checking it first keeps a hostile count from reserving gigabytes.
  if (count > in.Remaining() / kEntryHeaderSize) {
    detail = "entry count " + std::to_string(count) + " exceeds the payload";
    return false;
  }
  image.entries.reserve(count);
  for (std::uint32_t i = 0; i < count; ++i) {
    StoreEntry entry;
    std::uint16_t type = 0;
    std::uint8_t flags = 0;
    std::uint16_t length = 0;
    if (!in.Get16(entry.index) || !in.Get8(entry.sub_index) || !in.Get16(type) || !in.Get8(flags) ||
        !in.Get16(length) || !in.GetBytes(length, entry.value)) {
      detail = "entry " + std::to_string(i) + " runs past the end of the payload";
      return false;
    }
    if ((flags & ~kFlagNodeIdRelative) != 0) {
      detail = "entry " + std::to_string(i) + " has unknown flags " + Hex(flags, 2);
      return false;
    }
    entry.type = static_cast<DataType>(type);
    entry.node_id_relative = (flags & kFlagNodeIdRelative) != 0;
    image.entries.push_back(std::move(entry));
  }
  if (in.Remaining() != 0) {
    detail = std::to_string(in.Remaining()) + " bytes after the last entry";
    return false;
  }
  return true;
}

}  // namespace

const char* ToString(StoreProblem problem) {
  switch (problem) {
    case StoreProblem::kIoError:
      return "cannot be read";
    case StoreProblem::kTooLarge:
      return "too large";
    case StoreProblem::kEmpty:
      return "empty";
    case StoreProblem::kTruncated:
      return "truncated";
    case StoreProblem::kBadMagic:
      return "not a store file (magic)";
    case StoreProblem::kBadVersion:
      return "unknown format version";
    case StoreProblem::kBadHeader:
      return "bad header";
    case StoreProblem::kBadLength:
      return "length mismatch";
    case StoreProblem::kBadCrc:
      return "CRC mismatch (corrupt)";
    case StoreProblem::kForeign:
      return "foreign file";
    case StoreProblem::kMalformed:
      return "malformed";
    case StoreProblem::kNoSuchObject:
      return "object no longer exists";
    case StoreProblem::kTypeMismatch:
      return "data type differs";
    case StoreProblem::kSizeMismatch:
      return "size differs";
    case StoreProblem::kNotStorable:
      return "not storable";
    case StoreProblem::kOutOfRange:
      return "outside the object's limits";
    case StoreProblem::kOutsideGroup:
      return "outside the file's group";
    case StoreProblem::kRejected:
      return "rejected by the object dictionary";
  }
  return "unknown problem";
}

const char* ToString(StoreGroup group) {
  switch (group) {
    case StoreGroup::kCommunication:
      return "communication";
    case StoreGroup::kApplication:
      return "application";
    case StoreGroup::kManufacturer:
      return "manufacturer";
    case StoreGroup::kLss:
      return "LSS";
  }
  return "unknown group";
}

std::uint32_t Crc32(std::span<const std::uint8_t> data, std::uint32_t crc) {
  crc = ~crc;
  for (auto byte : data)
    crc = kCrcTable[(crc ^ byte) & 0xFF] ^ (crc >> 8);
  return ~crc;
}

Bytes EncodeStoreFile(const StoreImage& image) {
  Bytes out(kMagic.begin(), kMagic.end());
  Put16(out, kStoreFormatVersion);
  Put8(out, static_cast<std::uint8_t>(image.group));
  Put8(out, 0);
  Put32(out, 0);  // payload length, patched below
  Put32(out, 0);  // CRC, patched below
  Put32(out, image.vendor_id);
  Put32(out, image.product_code);
  if (image.group == StoreGroup::kLss) {
    Put8(out, image.lss.node_id);
    Put8(out, image.lss.bit_timing_index);
  } else {
    std::uint32_t count = 0;
    const std::size_t count_at = out.size();
    Put32(out, 0);
    for (const auto& entry : image.entries) {
      if (entry.value.size() > 0xFFFF) continue;
      Put16(out, entry.index);
      Put8(out, entry.sub_index);
      Put16(out, static_cast<std::uint16_t>(entry.type));
      Put8(out, entry.node_id_relative ? kFlagNodeIdRelative : 0);
      Put16(out, static_cast<std::uint16_t>(entry.value.size()));
      out.insert(out.end(), entry.value.begin(), entry.value.end());
      ++count;
    }
    Patch32(out, count_at, count);
  }
  const std::span<const std::uint8_t> payload(out.data() + kStoreHeaderSize, out.size() - kStoreHeaderSize);
  Patch32(out, 8, static_cast<std::uint32_t>(payload.size()));
  Patch32(out, 12, Crc32(payload));
  return out;
}

DecodeResult DecodeStoreFile(std::span<const std::uint8_t> bytes, StoreGroup expected) {
  if (bytes.empty()) return Fail(StoreProblem::kEmpty, "zero-length file");
  if (bytes.size() > kStoreMaxFileSize)
    return Fail(StoreProblem::kTooLarge, std::to_string(bytes.size()) + " bytes");
  // Check the magic on what is there before complaining about the length: a short foreign file
  // is foreign first.
  const std::size_t magic_bytes = std::min(bytes.size(), kMagic.size());
  if (!std::equal(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(magic_bytes), kMagic.begin()))
    return Fail(StoreProblem::kBadMagic, "magic is not \"CFPS\"");
  if (bytes.size() < kStoreHeaderSize)
    return Fail(StoreProblem::kTruncated, std::to_string(bytes.size()) + " bytes, header needs 16");

  Reader header(bytes.subspan(4, kStoreHeaderSize - 4));
  std::uint16_t version = 0;
  std::uint8_t group = 0;
  std::uint8_t reserved = 0;
  std::uint32_t length = 0;
  std::uint32_t crc = 0;
  header.Get16(version);
  header.Get8(group);
  header.Get8(reserved);
  header.Get32(length);
  header.Get32(crc);
  if (version != kStoreFormatVersion)
    return Fail(StoreProblem::kBadVersion,
                "version " + std::to_string(version) + ", expected " + std::to_string(kStoreFormatVersion));
  if (reserved != 0) return Fail(StoreProblem::kBadHeader, "reserved byte is " + Hex(reserved, 2));
  const std::size_t available = bytes.size() - kStoreHeaderSize;
  if (length > available)
    return Fail(StoreProblem::kTruncated,
                "payload " + std::to_string(available) + " of " + std::to_string(length) + " bytes");
  if (length < available)
    return Fail(StoreProblem::kBadLength, std::to_string(available - length) + " bytes after the payload");
  const auto payload = bytes.subspan(kStoreHeaderSize);
  if (auto actual = Crc32(payload); actual != crc)
    return Fail(StoreProblem::kBadCrc, "CRC " + Hex(actual, 8) + ", header says " + Hex(crc, 8));
  if (group != static_cast<std::uint8_t>(expected))
    return Fail(StoreProblem::kForeign, "holds group " + std::to_string(group) + ", expected " +
                                            std::to_string(static_cast<int>(expected)) + " (" +
                                            ToString(expected) + ")");

  StoreImage image;
  image.group = expected;
  Reader in(payload);
  if (payload.size() < kIdentitySize) return Fail(StoreProblem::kMalformed, "no identity");
  in.Get32(image.vendor_id);
  in.Get32(image.product_code);
  std::string detail;
  if (expected == StoreGroup::kLss) {
    if (!in.Get8(image.lss.node_id) || !in.Get8(image.lss.bit_timing_index) || in.Remaining() != 0)
      return Fail(StoreProblem::kMalformed, "LSS payload must be 10 bytes");
  } else if (!ParseEntries(in, image, detail)) {
    return Fail(StoreProblem::kMalformed, detail);
  }
  return {std::move(image), StoreProblem::kMalformed, {}};
}

}  // namespace canfleet::canopen
