// COB-ID EMCY 1014h (CiA 301 v4.2 §7.5.2.17): bit 31 = not valid, bit 29 = 29-bit CAN-ID, bits
// 0-28 = CAN-ID; writes checked as CANopenNode's OD_write_1014 does (06090030h).
#include "node/canopen/emcy/cob_id.hpp"

#include "tests/unit/emcy/emcy_fixture.hpp"

namespace canfleet::canopen {
namespace {

// Bit 31 = 1: the EMCY does not exist. Errors are still recorded; frames resume when it is valid.
TEST_F(EmcyTest, InvalidCobIdStopsFramesButNotBookkeeping) {
  auto& emcy = Start();
  ASSERT_EQ(WriteU32(0x1014, 0x80000085), SdoAbort::kNone);
  emcy.Raise(Error(0x2320, 0x0401, kErrorRegisterCurrent));
  EXPECT_EQ(probe.Count(), 0u);
  EXPECT_EQ(Get(0x1001), 0x03u);
  EXPECT_EQ(ErrorField(), std::vector<std::uint32_t>{0x04012320});
  ASSERT_EQ(WriteU32(0x1014, 0x00000085), SdoAbort::kNone);
  emcy.Clear(0x2320, 0x0401);
  EXPECT_EQ(probe.Take(), std::vector<std::string>{"085#0000000000000000"});
}

// §7.5.2.17: the CAN-ID may not change while the EMCY is valid; writing the same value is fine.
TEST_F(EmcyTest, CobIdCannotChangeWhileValid) {
  Start();
  EXPECT_EQ(WriteU32(0x1014, 0x00000086), SdoAbort::kInvalidValue);
  EXPECT_EQ(WriteU32(0x1014, 0x20000085), SdoAbort::kInvalidValue);  // frame format is part of it
  EXPECT_EQ(WriteU32(0x1014, 0x00000085), SdoAbort::kNone);
  EXPECT_EQ(Get(0x1014), 0x85u);
}

// CANopenNode rejects bits 11-30 with an 11-bit CAN-ID.
TEST_F(EmcyTest, CobIdRejectsReservedAndHighBits) {
  Start();
  EXPECT_EQ(WriteU32(0x1014, 0xC0000085), SdoAbort::kInvalidValue);  // bit 30
  EXPECT_EQ(WriteU32(0x1014, 0x80000885), SdoAbort::kInvalidValue);  // bit 11
  EXPECT_EQ(WriteU32(0x1014, 0x90000085), SdoAbort::kInvalidValue);  // bit 28
  EXPECT_EQ(Get(0x1014), 0x85u);
}

// Restricted CAN-IDs (CANopenNode CO_IS_RESTRICTED_CAN_ID), even while marking the EMCY invalid.
TEST_F(EmcyTest, CobIdRejectsRestrictedCanIds) {
  Start();
  ASSERT_EQ(WriteU32(0x1014, 0x80000085), SdoAbort::kNone);
  for (std::uint32_t id :
       {0x000u, 0x07Fu, 0x101u, 0x180u, 0x581u, 0x5FFu, 0x601u, 0x67Fu, 0x6E0u, 0x6FFu, 0x701u, 0x7FFu}) {
    EXPECT_EQ(WriteU32(0x1014, id), SdoAbort::kInvalidValue) << std::hex << id;
    EXPECT_EQ(WriteU32(0x1014, 0x80000000 | id), SdoAbort::kInvalidValue) << std::hex << id;
  }
  for (std::uint32_t id : {0x080u, 0x100u, 0x181u, 0x580u, 0x600u, 0x680u, 0x6DFu, 0x700u}) {
    EXPECT_EQ(WriteU32(0x1014, 0x80000000 | id), SdoAbort::kNone) << std::hex << id;
  }
}

// Changing the COB-ID takes two writes: invalidate, then the new ID with bit 31 = 0. A custom
// CAN-ID no longer follows the node-ID.
TEST_F(EmcyTest, CobIdChangeGoesThroughInvalid) {
  auto& emcy = Start();
  ASSERT_EQ(WriteU32(0x1014, 0x80000085), SdoAbort::kNone);
  ASSERT_EQ(WriteU32(0x1014, 0x000000A5), SdoAbort::kNone);
  emcy.Raise(Error(0x5000));
  EXPECT_EQ(probe.Take(), std::vector<std::string>{"0A5#0050010000000000"});
  emcy.SetNodeId(6);
  EXPECT_EQ(Get(0x1014), 0xA5u);
  emcy.Clear(0x5000, 0);
  EXPECT_EQ(probe.Take(), std::vector<std::string>{"0A5#0000000000000000"});
}

// Writing 80h + node-ID back makes the COB-ID the default again (CANopenNode stores 80h).
TEST_F(EmcyTest, WritingTheDefaultBackFollowsTheNodeIdAgain) {
  auto& emcy = Start();
  ASSERT_EQ(WriteU32(0x1014, 0x80000085), SdoAbort::kNone);
  ASSERT_EQ(WriteU32(0x1014, 0x00000085), SdoAbort::kNone);
  emcy.SetNodeId(6);
  EXPECT_EQ(Get(0x1014), 0x86u);
  emcy.Raise(Error(0x5000));
  EXPECT_EQ(probe.Take(), std::vector<std::string>{"086#0050010000000000"});
}

// Bit 29 = 1: a 29-bit CAN-ID, sent as a CAN extended frame.
TEST_F(EmcyTest, ExtendedCobIdSendsAnExtendedFrame) {
  auto& emcy = Start();
  ASSERT_EQ(WriteU32(0x1014, 0x80000085), SdoAbort::kNone);
  ASSERT_EQ(WriteU32(0x1014, 0x20012345), SdoAbort::kNone);
  EXPECT_EQ(Get(0x1014), 0x20012345u);
  emcy.Raise(Error(0x5000));
  EXPECT_EQ(probe.Take(), std::vector<std::string>{"00012345#0050010000000000"});
}

TEST(EmcyCobId, DecodeAndEncodeRoundTrip) {
  for (std::uint32_t value : {0x00000085u, 0x80000085u, 0x20012345u, 0xA1FFFFFFu}) {
    EXPECT_EQ(EmcyCobId::Decode(value).Encode(), value) << std::hex << value;
  }
  auto c = EmcyCobId::Decode(0xA0012345);
  EXPECT_FALSE(c.valid);
  EXPECT_TRUE(c.extended);
  EXPECT_EQ(c.can_id, 0x12345u);
}

TEST(EmcyCobId, ValidationFollowsCanopenNode) {
  EXPECT_EQ(ValidateEmcyCobIdWrite(0x85, 0x85), SdoAbort::kNone);
  EXPECT_EQ(ValidateEmcyCobIdWrite(0x85, 0x80000085), SdoAbort::kNone);
  EXPECT_EQ(ValidateEmcyCobIdWrite(0x85, 0x80000099), SdoAbort::kNone);  // invalidating may change it
  EXPECT_EQ(ValidateEmcyCobIdWrite(0x85, 0x99), SdoAbort::kInvalidValue);
  EXPECT_EQ(ValidateEmcyCobIdWrite(0x80000085, 0x99), SdoAbort::kNone);
  EXPECT_EQ(ValidateEmcyCobIdWrite(0x80000085, 0x3FFFFFFF), SdoAbort::kNone);  // 29-bit: all of bits 0-28
  EXPECT_EQ(ValidateEmcyCobIdWrite(0x80000085, 0x20000001), SdoAbort::kNone);  // no restriction for 29-bit
  EXPECT_EQ(ValidateEmcyCobIdWrite(0x80000085, 0x00000001), SdoAbort::kInvalidValue);
}

}  // namespace
}  // namespace canfleet::canopen
