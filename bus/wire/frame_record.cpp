#include "bus/wire/frame_record.hpp"

#include <algorithm>
#include <bit>

namespace canfleet::wire {

namespace {

constexpr std::uint8_t kKnownFlags = CanFrame::kExtended | CanFrame::kRemote | CanFrame::kError;

template <class T>
T LoadLittle(const std::uint8_t* in) {
  if constexpr (std::endian::native == std::endian::little) {
    T value;
    std::memcpy(&value, in, sizeof(T));
    return value;
  } else {
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i)
      v |= static_cast<std::uint64_t>(in[i]) << (8 * i);
    return static_cast<T>(v);
  }
}

}  // namespace

bool ValidateRecord(const std::uint8_t* record, std::string& error) {
  const std::uint32_t id = LoadLittle<std::uint32_t>(record + 8);
  const std::uint8_t dlc = record[12];
  const std::uint8_t flags = record[13];
  if (dlc > 8) {
    error = "DLC " + std::to_string(dlc) + " above 8";
    return false;
  }
  if ((flags & ~kKnownFlags) != 0) {
    error = "unknown flag bits " + std::to_string(flags);
    return false;
  }
  const bool extended = (flags & CanFrame::kExtended) != 0;
  if (id > (extended ? CanFrame::kMaxExtendedId : CanFrame::kMaxStandardId)) {
    error = "identifier " + std::to_string(id) + " too large for its format";
    return false;
  }
  if (record[14] != 0 || record[15] != 0) {
    error = "reserved bytes not zero";
    return false;
  }
  return true;
}

namespace {

/// The common case of ValidateRecord, branch-light and without building a message.
inline bool RecordOk(const std::uint8_t* record) {
  const std::uint32_t id = LoadLittle<std::uint32_t>(record + 8);
  const std::uint8_t flags = record[13];
  const std::uint32_t max_id =
      (flags & CanFrame::kExtended) != 0 ? CanFrame::kMaxExtendedId : CanFrame::kMaxStandardId;
  return static_cast<bool>((record[12] <= 8) & ((flags & ~kKnownFlags) == 0) & (id <= max_id) &
                           ((record[14] | record[15]) == 0));
}

}  // namespace

bool ValidateRecords(std::span<const std::uint8_t> bytes, std::string& error) {
  if (bytes.size() % kFrameRecordSize != 0) {
    error = "frame records of " + std::to_string(bytes.size()) + " bytes: not a multiple of " +
            std::to_string(kFrameRecordSize);
    return false;
  }
  for (std::size_t offset = 0; offset < bytes.size(); offset += kFrameRecordSize) {
    if (RecordOk(bytes.data() + offset)) continue;
    ValidateRecord(bytes.data() + offset, error);  // says why
    error = "frame record " + std::to_string(offset / kFrameRecordSize) + ": " + error;
    return false;
  }
  return true;
}

}  // namespace canfleet::wire
