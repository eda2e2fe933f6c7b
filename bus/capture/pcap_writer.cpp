#include "bus/capture/pcap_writer.hpp"

#include <algorithm>

#include "bus/capture/socketcan_layout.hpp"

namespace canfleet::capture {
namespace {

void PutLe16(std::uint8_t* p, std::uint16_t v) {
  p[0] = static_cast<std::uint8_t>(v);
  p[1] = static_cast<std::uint8_t>(v >> 8);
}
void PutLe32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i)
    p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
void PutBe32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i)
    p[i] = static_cast<std::uint8_t>(v >> (8 * (3 - i)));
}

}  // namespace

std::array<std::uint8_t, kPcapGlobalHeaderSize> PcapGlobalHeader() {
  std::array<std::uint8_t, kPcapGlobalHeaderSize> h{};
  PutLe32(&h[0], kPcapMagicMicroseconds);
  PutLe16(&h[4], 2);  // version_major
  PutLe16(&h[6], 4);  // version_minor
  // thiszone (4 bytes) and sigfigs (4 bytes) stay 0
  PutLe32(&h[16], kPcapSnaplen);
  PutLe32(&h[20], kLinktypeCanSocketcan);
  return h;
}

std::array<std::uint8_t, kPcapRecordSize> PcapRecord(const CanFrame& frame, WallTime time) {
  std::array<std::uint8_t, kPcapRecordSize> r{};
  const auto us = std::chrono::floor<std::chrono::microseconds>(time.time_since_epoch()).count();
  const std::uint64_t total_us = us < 0 ? 0 : static_cast<std::uint64_t>(us);
  // pcap's ts_sec is 32 bits (unsigned by convention): valid until 2106.
  PutLe32(&r[0], static_cast<std::uint32_t>(total_us / 1'000'000));
  PutLe32(&r[4], static_cast<std::uint32_t>(total_us % 1'000'000));
  PutLe32(&r[8], kSocketCanFrameSize);
  PutLe32(&r[12], kSocketCanFrameSize);

  const SocketCanFrame f = ToSocketCan(frame);
  std::uint8_t* p = &r[kPcapRecordHeaderSize];
  PutBe32(p, f.can_id);
  p[4] = f.len;
  std::copy(f.data.begin(), f.data.end(), p + 8);
  return r;
}

PcapWriter::PcapWriter(const std::filesystem::path& path) : file_(path) {
  file_.Append(PcapGlobalHeader());
}

void PcapWriter::Write(const CanFrame& frame, WallTime time) {
  file_.Append(PcapRecord(frame, time));
}

}  // namespace canfleet::capture
