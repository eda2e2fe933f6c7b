#include "bus/physics/frame_timing.hpp"

#include <array>

namespace canfleet {

namespace {

/// The bits of a frame from SOF to the end of the data field, most significant bit first,
/// dominant = 0. At most 1 + 32 + 6 + 64 = 103 bits (29-bit with 8 data bytes).
struct BitString {
  std::array<std::uint8_t, 128> bits{};
  std::uint32_t size = 0;
  void Push(std::uint32_t value, std::uint32_t count) {
    for (std::uint32_t i = count; i-- > 0;)
      bits[size++] = static_cast<std::uint8_t>((value >> i) & 1U);
  }
};

BitString HeaderAndData(const CanFrame& f) {
  BitString s;
  const std::uint32_t rtr = f.remote() ? 1 : 0;
  s.Push(0, 1);  // SOF
  if (f.extended()) {
    s.Push(f.id >> 18, 11);  // base identifier
    s.Push(1, 1);            // SRR (recessive)
    s.Push(1, 1);            // IDE (recessive: extended)
    s.Push(f.id & 0x3FFFF, 18);
    s.Push(rtr, 1);
    s.Push(0, 2);  // r1, r0
  } else {
    s.Push(f.id, 11);
    s.Push(rtr, 1);
    s.Push(0, 1);  // IDE (dominant: standard)
    s.Push(0, 1);  // r0
  }
  s.Push(f.dlc, 4);
  if (!f.remote()) {
    for (std::uint32_t i = 0; i < f.dlc && i < 8; ++i)
      s.Push(f.data[i], 8);
  }
  return s;
}

std::uint16_t Crc15(const BitString& s) {
  std::uint16_t crc = 0;
  for (std::uint32_t i = 0; i < s.size; ++i) {
    bool next = ((crc >> 14) & 1U) != s.bits[i];
    crc = static_cast<std::uint16_t>((crc << 1) & 0x7FFF);
    if (next) crc ^= 0x4599;
  }
  return crc;
}

}  // namespace

std::uint16_t CanCrc15(const CanFrame& frame) {
  return Crc15(HeaderAndData(frame));
}

FrameBits CountFrameBits(const CanFrame& frame) {
  BitString s = HeaderAndData(frame);
  s.Push(Crc15(s), 15);
  FrameBits out;
  out.unstuffed = s.size;
  // After five equal bits the transmitter inserts one of the opposite level; the stuff bit
  // starts the next run (ISO 11898-1 §10.5).
  std::uint8_t last = s.bits[0];
  std::uint32_t run = 1;
  for (std::uint32_t i = 1; i < s.size; ++i) {
    if (s.bits[i] == last) {
      ++run;
    } else {
      last = s.bits[i];
      run = 1;
    }
    if (run == 5) {
      ++out.stuff;
      last = static_cast<std::uint8_t>(!last);
      run = 1;
    }
  }
  return out;
}

std::uint32_t MaxFrameBits(std::uint8_t dlc, bool extended, bool remote) {
  std::uint32_t data = remote ? 0 : 8U * (dlc > 8 ? 8 : dlc);
  std::uint32_t stuffed_region = (extended ? 39U : 19U) + data + 15U;
  // Worst case: one stuff bit after the first 5 bits, then one every 4 bits.
  return stuffed_region + (stuffed_region - 1) / 4 + kFrameTailBits + kIntermissionBits;
}

}  // namespace canfleet
