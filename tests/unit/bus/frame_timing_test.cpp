// Frame length on the wire, ISO 11898-1 §10.4 (frame format) and §10.5 (bit stuffing).
#include "bus/physics/frame_timing.hpp"

#include <gtest/gtest.h>

#include <random>

#include "tests/support/bus_probe.hpp"

namespace canfleet {
namespace {

using test::Frame;

// Worked by hand: SOF + 11-bit id 0 + RTR/IDE/r0 + DLC 0 = 19 dominant bits, CRC-15 of zeros = 0,
// so 34 dominant bits: a stuff bit after every 5 → 6 stuff bits; 34 + 6 + 10 + 3 = 53.
TEST(FrameTiming, AllDominantEmptyFrameWorkedByHand) {
  auto bits = CountFrameBits(Frame("000#"));
  EXPECT_EQ(CanCrc15(Frame("000#")), 0);
  EXPECT_EQ(bits.unstuffed, 34u);
  EXPECT_EQ(bits.stuff, 6u);
  EXPECT_EQ(bits.total(), 53u);
}

// Worked by hand: 0 11111111111 0000000 then CRC 0x272F = 010011100101111:
// stuff after the 5th and 10th recessive id bit, and after the 5th of the 7 dominant bits → 3.
TEST(FrameTiming, RecessiveIdEmptyFrameWorkedByHand) {
  EXPECT_EQ(CanCrc15(Frame("7FF#")), 0x272F);
  auto bits = CountFrameBits(Frame("7FF#"));
  EXPECT_EQ(bits.unstuffed, 34u);
  EXPECT_EQ(bits.stuff, 3u);
}

TEST(FrameTiming, ReferenceFrames) {
  struct Case {
    const char* frame;
    std::uint16_t crc;
    std::uint32_t unstuffed, stuff;
  };
  for (auto c :
       {Case{"123#1122334455667788", 0x4237, 98, 1}, Case{"701#05", 0x4D0E, 42, 3},
        Case{"1ABCDEF0#AA55", 0x7B54, 70, 3}, Case{"705#R1", 0x3435, 34, 2},
        Case{"000#0000000000000000", 0x145B, 98, 16}, Case{"7FF#FFFFFFFFFFFFFFFF", 0x4C89, 98, 15}}) {
    SCOPED_TRACE(c.frame);
    EXPECT_EQ(CanCrc15(Frame(c.frame)), c.crc);
    auto bits = CountFrameBits(Frame(c.frame));
    EXPECT_EQ(bits.unstuffed, c.unstuffed);
    EXPECT_EQ(bits.stuff, c.stuff);
  }
}

// The known bounds: an 8-byte 11-bit data frame is 111 bits without stuffing (intermission
// included) and at most 135 with it; a 29-bit one 131 and at most 160.
TEST(FrameTiming, KnownBoundsForEightByteFrames) {
  EXPECT_EQ(MaxFrameBits(8, false), 135u);
  EXPECT_EQ(MaxFrameBits(8, true), 160u);
  EXPECT_EQ(CountFrameBits(Frame("123#1122334455667788")).unstuffed + kFrameTailBits + kIntermissionBits,
            111u);
  EXPECT_EQ(CountFrameBits(Frame("1ABCDEF0#1122334455667788")).unstuffed + kFrameTailBits + kIntermissionBits,
            131u);
}

TEST(FrameTiming, RandomFramesStayWithinBounds) {
  std::mt19937 rng(7);
  for (int i = 0; i < 20000; ++i) {
    CanFrame f;
    bool ext = rng() & 1;
    f.flags = static_cast<std::uint8_t>((ext ? CanFrame::kExtended : 0) |
                                        ((rng() % 8 == 0) ? CanFrame::kRemote : 0));
    f.id = static_cast<std::uint32_t>(rng()) & (ext ? CanFrame::kMaxExtendedId : CanFrame::kMaxStandardId);
    f.dlc = static_cast<std::uint8_t>(rng() % 9);
    for (auto& b : f.data)
      b = static_cast<std::uint8_t>(rng());
    auto bits = CountFrameBits(f);
    ASSERT_LE(bits.total(), MaxFrameBits(f.dlc, ext, f.remote())) << ToCandump(f);
    ASSERT_EQ(bits.unstuffed + kFrameTailBits + kIntermissionBits,
              (ext ? 39u : 19u) + (f.remote() ? 0u : 8u * f.dlc) + 15u + 13u);
  }
}

TEST(FrameTiming, DurationAtBitrate) {
  EXPECT_EQ(BitTime(111, 1'000'000), std::chrono::nanoseconds(111'000));
  EXPECT_EQ(BitTime(kBusOffRecoveryBits, 125'000), std::chrono::microseconds(11'264));
}

}  // namespace
}  // namespace canfleet
