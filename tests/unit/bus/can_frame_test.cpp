#include "bus/can_frame.hpp"

#include <gtest/gtest.h>

#include "tests/support/bus_probe.hpp"

namespace canfleet {
namespace {

TEST(CanFrame, IsSixteenBytesAndValidatesIdAndDlc) {
  EXPECT_TRUE(CanFrame::Data(0x7FF, {1, 2}).valid());
  CanFrame too_big_id = CanFrame::Data(0x800, {});
  EXPECT_FALSE(too_big_id.valid());
  too_big_id.flags |= CanFrame::kExtended;
  EXPECT_TRUE(too_big_id.valid());
  CanFrame bad_dlc;
  bad_dlc.dlc = 9;
  EXPECT_FALSE(bad_dlc.valid());
}

TEST(CanFrame, CandumpNotationRoundTrips) {
  for (const char* text : {"123#DEADBEEF", "000#", "701#R", "701#R1", "1ABCDEF0#0011223344556677"}) {
    EXPECT_EQ(ToCandump(test::Frame(text)), text);
  }
}

TEST(CanFrame, EqualityIgnoresBytesBeyondDlc) {
  CanFrame a = CanFrame::Data(0x181, {1, 2});
  CanFrame b = a;
  b.data[5] = 0x55;
  EXPECT_EQ(a, b);
  b.data[1] = 0x55;
  EXPECT_NE(a, b);
}

TEST(CanFrame, RemoteFrameHasNoPayload) {
  auto f = CanFrame::Remote(0x705, 1);
  EXPECT_TRUE(f.remote());
  EXPECT_TRUE(f.payload().empty());
}

}  // namespace
}  // namespace canfleet
