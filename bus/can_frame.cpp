#include "bus/can_frame.hpp"

#include <algorithm>
#include <cstdio>

namespace canfleet {

CanFrame CanFrame::Data(std::uint32_t id, std::span<const std::uint8_t> bytes) {
  CanFrame f;
  f.id = id;
  f.dlc = static_cast<std::uint8_t>(std::min<std::size_t>(bytes.size(), 8));
  std::copy_n(bytes.begin(), f.dlc, f.data.begin());
  return f;
}

CanFrame CanFrame::Data(std::uint32_t id, std::initializer_list<std::uint8_t> bytes) {
  return Data(id, std::span<const std::uint8_t>(bytes.begin(), bytes.size()));
}

CanFrame CanFrame::Remote(std::uint32_t id, std::uint8_t dlc) {
  CanFrame f;
  f.id = id;
  f.dlc = dlc;
  f.flags = kRemote;
  return f;
}

bool operator==(const CanFrame& a, const CanFrame& b) {
  if (a.id != b.id || a.dlc != b.dlc || a.flags != b.flags) return false;
  // Bytes beyond the DLC are not part of the frame.
  auto n = a.remote() ? 0 : std::min<int>(a.dlc, 8);
  return std::equal(a.data.begin(), a.data.begin() + n, b.data.begin());
}

std::string ToCandump(const CanFrame& frame) {
  char buf[40];
  int n = frame.extended() ? std::snprintf(buf, sizeof buf, "%08X#", frame.id)
                           : std::snprintf(buf, sizeof buf, "%03X#", frame.id);
  std::string out(buf, static_cast<std::size_t>(n));
  if (frame.remote()) {
    out += 'R';
    if (frame.dlc != 0) out += static_cast<char>('0' + std::min<int>(frame.dlc, 8));
    return out;
  }
  for (auto b : frame.payload()) {
    std::snprintf(buf, sizeof buf, "%02X", b);
    out += buf;
  }
  return out;
}

}  // namespace canfleet
