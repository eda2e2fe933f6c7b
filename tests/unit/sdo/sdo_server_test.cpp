// SDO server, expedited and segmented transfers and the server's configuration: CiA 301 v4.2
// §7.2.4.3.2–7 (protocols), §7.2.4.3.17 (abort), §7.5.2.33 (1200h), §7.3.2.2 (SDO per NMT state).
// Node 5: the probe (client) sends on 605h, the server answers on 585h.
#include "node/canopen/sdo/sdo_server.hpp"

#include <gtest/gtest.h>

#include "tests/unit/sdo/sdo_test_bench.hpp"

namespace canfleet::canopen {
namespace {

using namespace std::chrono_literals;
using test::ServerBench;

class SdoServerTest : public ::testing::Test {
 protected:
  ServerBench b;
  canfleet::test::BusProbe& probe = b.probe;
};

// ---- expedited (§7.2.4.3.3, §7.2.4.3.6) ----------------------------------------------------------

TEST_F(SdoServerTest, ExpeditedUploadOfFourBytes) {
  probe.Send("605#4000100000000000");
  EXPECT_EQ(probe.Next(), "585#4300100094010F00");
  EXPECT_EQ(probe.Count(), 0u);
}

TEST_F(SdoServerTest, ExpeditedUploadIndicatesTheSizeInN) {
  b.od.SetUnsigned(0x1017, 0, 0x03E8);
  probe.Send("605#4017100000000000");
  EXPECT_EQ(probe.Next(), "585#4B171000E8030000");  // n = 2: two bytes
  probe.Send("605#4000200000000000");
  EXPECT_EQ(probe.Next(), "585#4F00200000000000");  // n = 3: one byte
}

TEST_F(SdoServerTest, ExpeditedDownloadWithSizeIndicated) {
  probe.Send("605#2B171000E8030000");
  EXPECT_EQ(probe.Next(), "585#6017100000000000");
  EXPECT_EQ(b.od.GetUnsigned(0x1017, 0), 1000u);
}

TEST_F(SdoServerTest, ExpeditedDownloadWithoutSizeWritesTheObjectsSize) {
  // 22h: e = 1, s = 0. The size comes from the object: two bytes of U16, four of U32.
  probe.Send("605#22171000341299AA");
  EXPECT_EQ(probe.Next(), "585#6017100000000000");
  EXPECT_EQ(b.od.GetUnsigned(0x1017, 0), 0x1234u);
  probe.Send("605#2201200020000000");
  EXPECT_EQ(probe.Next(), "585#6001200000000000");
  EXPECT_EQ(b.od.GetUnsigned(0x2001, 0), 32u);
}

TEST_F(SdoServerTest, ExpeditedDownloadHonoursNForEachSize) {
  probe.Send("605#2F002000AB000000");  // 1 byte
  EXPECT_EQ(probe.Next(), "585#6000200000000000");
  EXPECT_EQ(b.od.GetUnsigned(0x2000, 0), 0xABu);
  probe.Send("605#2704200001020300");  // 3 bytes to a DOMAIN
  EXPECT_EQ(probe.Next(), "585#6004200000000000");
  EXPECT_EQ(b.od.Find(0x2004, 0)->value, (Bytes{1, 2, 3}));
}

// ---- segmented (§7.2.4.3.2–7) ------------------------------------------------------------------

TEST_F(SdoServerTest, SegmentedUploadAlternatesTheToggleBit) {
  probe.Send("605#4008100000000000");
  EXPECT_EQ(probe.Next(), "585#410810000F000000");  // 15 bytes
  probe.Send("605#6000000000000000");
  EXPECT_EQ(probe.Next(), "585#0063616E666C6565");  // t = 0: "canflee"
  probe.Send("605#7000000000000000");
  EXPECT_EQ(probe.Next(), "585#1074207365727665");  // t = 1: "t serve"
  probe.Send("605#6000000000000000");
  EXPECT_EQ(probe.Next(), "585#0D72000000000000");  // t = 0, n = 6, c = 1: "r"
  EXPECT_FALSE(b.server.Busy());
}

TEST_F(SdoServerTest, SegmentedUploadOfAMultipleOfSevenEndsWithAFullSegment) {
  b.od.Write(0x2004, 0, Bytes{1, 2, 3, 4, 5, 6, 7}, Origin::kDevice);
  probe.Send("605#4004200000000000");
  EXPECT_EQ(probe.Next(), "585#4104200007000000");
  probe.Send("605#6000000000000000");
  EXPECT_EQ(probe.Next(), "585#0101020304050607");  // n = 0, c = 1
}

TEST_F(SdoServerTest, SegmentedUploadOfAnEmptyValue) {
  probe.Send("605#4004200000000000");
  EXPECT_EQ(probe.Next(), "585#4104200000000000");
  probe.Send("605#6000000000000000");
  EXPECT_EQ(probe.Next(), "585#0F00000000000000");  // n = 7, c = 1
}

TEST_F(SdoServerTest, SegmentedDownloadAlternatesTheToggleAndCommitsAtTheEnd) {
  probe.Send("605#210420000A000000");
  EXPECT_EQ(probe.Next(), "585#6004200000000000");
  probe.Send("605#0030313233343536");
  EXPECT_EQ(probe.Next(), "585#2000000000000000");
  EXPECT_TRUE(b.od.Find(0x2004, 0)->value.empty());  // nothing written before the transfer is complete
  probe.Send("605#1937383900000000");                // t = 1, n = 4, c = 1
  EXPECT_EQ(probe.Next(), "585#3000000000000000");
  EXPECT_EQ(b.od.Find(0x2004, 0)->value, ToBytes("0123456789"));
}

TEST_F(SdoServerTest, SegmentedDownloadWithoutSizeIndicated) {
  probe.Send("605#2004200000000000");
  EXPECT_EQ(probe.Next(), "585#6004200000000000");
  probe.Send("605#0941424300000000");  // t = 0, n = 4, c = 1: "ABC"
  EXPECT_EQ(probe.Next(), "585#2000000000000000");
  EXPECT_EQ(b.od.Find(0x2004, 0)->value, ToBytes("ABC"));
}

TEST_F(SdoServerTest, SegmentedDownloadOfAFixedSizeObject) {
  probe.Send("605#2106200008000000");
  EXPECT_EQ(probe.Next(), "585#6006200000000000");
  probe.Send("605#0001020304050607");
  EXPECT_EQ(probe.Next(), "585#2000000000000000");
  probe.Send("605#1D08000000000000");  // t = 1, n = 6, c = 1
  EXPECT_EQ(probe.Next(), "585#3000000000000000");
  EXPECT_EQ(b.od.GetUnsigned(0x2006, 0), 0x0807060504030201u);
}

TEST_F(SdoServerTest, AFailedSegmentedDownloadLeavesTheOldValue) {
  b.od.Write(0x2004, 0, ToBytes("old"), Origin::kDevice);
  probe.Send("605#210420000A000000");
  probe.Send("605#0030313233343536");
  probe.Send("605#0037383900000000");  // toggle not alternated
  probe.Take();
  EXPECT_EQ(b.od.Find(0x2004, 0)->value, ToBytes("old"));
}

// ---- dispatch rules ----------------------------------------------------------------------------

TEST_F(SdoServerTest, ClientAbortCancelsSilently) {
  // §7.2.4.3.17: the abort transfer service is unconfirmed.
  probe.Send("605#210420000A000000");
  probe.Take();
  probe.Send("605#8004200000000008");
  EXPECT_EQ(probe.Count(), 0u);
  EXPECT_FALSE(b.server.Busy());
  probe.Send("605#0030313233343536");  // the transfer is gone
  EXPECT_EQ(probe.Next(), "585#8000000001000405");
}

TEST_F(SdoServerTest, ANewInitiateRestartsWithoutAbort) {
  probe.Send("605#4008100000000000");
  probe.Send("605#6000000000000000");
  probe.Take();
  probe.Send("605#4000100000000000");  // new request in the middle of a segmented upload
  EXPECT_EQ(probe.Next(), "585#4300100094010F00");
  EXPECT_EQ(probe.Count(), 0u);
  probe.Send("605#2B171000E8030000");
  EXPECT_EQ(probe.Next(), "585#6017100000000000");
}

TEST_F(SdoServerTest, FramesWithDlcOtherThanEightAreIgnored) {
  // CiA 301 §7.2.4.3.1: SDO frames are 8 bytes; CANopenNode's CO_SDO_receive ignores the rest.
  EXPECT_TRUE(b.server.OnFrame(canfleet::test::Frame("605#40001000")));
  EXPECT_TRUE(b.server.OnFrame(canfleet::test::Frame("605#R8")));
  probe.Send("605#40001000000000");  // 7 bytes
  probe.Send("605#R");
  EXPECT_EQ(probe.Count(), 0u);
}

TEST_F(SdoServerTest, ShortFramesDoNotDisturbATransfer) {
  probe.Send("605#210420000A000000");
  probe.Take();
  probe.Send("605#00303132");
  probe.Send("605#");
  EXPECT_EQ(probe.Count(), 0u);
  probe.Send("605#0030313233343536");
  EXPECT_EQ(probe.Next(), "585#2000000000000000");
}

TEST_F(SdoServerTest, OtherIdentifiersAreNotConsumed) {
  EXPECT_FALSE(b.server.OnFrame(canfleet::test::Frame("606#4000100000000000")));
  EXPECT_FALSE(b.server.OnFrame(canfleet::test::Frame("585#4000100000000000")));
  EXPECT_FALSE(b.server.OnFrame(canfleet::test::Frame("00000605#4000100000000000")));  // 29-bit
  EXPECT_TRUE(b.server.OnFrame(canfleet::test::Frame("605#4000100000000000")));
}

// ---- enabling (§7.3.2.2, table 51) ---------------------------------------------------------------

TEST_F(SdoServerTest, DisabledServerIgnoresFrames) {
  b.server.SetEnabled(false);
  EXPECT_FALSE(b.server.OnFrame(canfleet::test::Frame("605#4000100000000000")));
  probe.Send("605#4000100000000000");
  EXPECT_EQ(probe.Count(), 0u);
  b.server.SetEnabled(true);
  probe.Send("605#4000100000000000");
  EXPECT_EQ(probe.Next(), "585#4300100094010F00");
}

TEST_F(SdoServerTest, DisablingDropsATransferSilently) {
  probe.Send("605#4008100000000000");
  probe.Take();
  b.server.SetEnabled(false);
  EXPECT_FALSE(b.server.Busy());
  b.scheduler.Advance(5s);  // no timeout abort either
  EXPECT_EQ(probe.Count(), 0u);
  b.server.SetEnabled(true);
  probe.Send("605#6000000000000000");
  EXPECT_EQ(probe.Next(), "585#8000000001000405");
}

// ---- COB-IDs (§7.3.5, §7.5.2.33) ---------------------------------------------------------------

TEST_F(SdoServerTest, SetNodeIdChangesTheCobIds) {
  b.server.SetNodeId(0x20);
  EXPECT_EQ(b.server.RequestCobId(), 0x620u);
  EXPECT_EQ(b.server.ResponseCobId(), 0x5A0u);
  probe.Send("605#4000100000000000");
  EXPECT_EQ(probe.Count(), 0u);
  probe.Send("620#4000100000000000");
  EXPECT_EQ(probe.Next(), "5A0#4300100094010F00");
  // 1200h shows the COB-IDs in use.
  probe.Send("620#4000120100000000");
  EXPECT_EQ(probe.Next(), "5A0#4300120120060000");
  probe.Send("620#4000120200000000");
  EXPECT_EQ(probe.Next(), "5A0#43001202A0050000");
}

TEST_F(SdoServerTest, WithoutObject1200TheDefaultCobIdsAreUsed) {
  ObjectDictionary od;
  od.AddVar(0x1000, "Device type", DataType::kUnsigned32, Access::kRo, EncodeLe<std::uint32_t>(0x191));
  LoopbackPort& port = b.bus.Attach("other node");
  SdoServer server(od, port, b.scheduler);
  port.OnReceive([&](const CanFrame& frame, BusTime) { server.OnFrame(frame); });
  server.SetNodeId(0x7F);
  probe.Send("67F#4000100000000000");
  EXPECT_EQ(probe.Next(), "5FF#4300100091010000");
}

TEST_F(SdoServerTest, SetNodeIdAbortsATransferInProgressOnTheOldCobId) {
  probe.Send("605#4008100000000000");
  probe.Take();
  b.server.SetNodeId(6);
  EXPECT_EQ(probe.Next(), "585#8008100023000A06");  // 060A0023: no SDO connection
  EXPECT_FALSE(b.server.Busy());
}

TEST_F(SdoServerTest, InvalidNodeIdLeavesTheServerDeaf) {
  b.server.SetNodeId(0xFF);  // LSS-unconfigured
  EXPECT_FALSE(b.server.OnFrame(canfleet::test::Frame("605#4000100000000000")));
  EXPECT_FALSE(b.server.OnFrame(canfleet::test::Frame("67F#4000100000000000")));
  b.server.SetNodeId(5);
  EXPECT_TRUE(b.server.OnFrame(canfleet::test::Frame("605#4000100000000000")));
}

TEST_F(SdoServerTest, DeviceWritesOf1200hMoveTheServer) {
  b.od.SetUnsigned(0x1200, 1, 0x611);
  b.od.SetUnsigned(0x1200, 2, 0x591);
  probe.Send("611#4000100000000000");
  EXPECT_EQ(probe.Next(), "591#4300100094010F00");
  b.od.SetUnsigned(0x1200, 1, 0x80000611);  // bit 31: SDO not valid
  EXPECT_FALSE(b.server.OnFrame(canfleet::test::Frame("611#4000100000000000")));
}

TEST_F(SdoServerTest, RestoreDefaultsOf1200hFollowsTheNodeId) {
  b.od.RestoreDefaults(0x1000, 0x1FFF, 9);  // what reset communication does with a new node-ID
  probe.Send("609#4000100000000000");
  EXPECT_EQ(probe.Next(), "589#4300100094010F00");
}

TEST_F(SdoServerTest, ExtendedCobIdsUse29BitFrames) {
  b.od.SetUnsigned(0x1200, 1, 0x20001605);
  b.od.SetUnsigned(0x1200, 2, 0x20001585);
  EXPECT_FALSE(b.server.OnFrame(canfleet::test::Frame("605#4000100000000000")));
  probe.Send("00001605#4000100000000000");
  EXPECT_EQ(probe.Next(), "00001585#4300100094010F00");
}

TEST(AddSdoServerObjects, Creates1200hWithNodeIdRelativeDefaults) {
  ObjectDictionary od;
  AddSdoServerObjects(od);
  const Object* obj = od.Find(0x1200);
  ASSERT_NE(obj, nullptr);
  EXPECT_EQ(obj->code, ObjectCode::kRecord);
  EXPECT_EQ(od.GetUnsigned(0x1200, 0), 2u);
  EXPECT_EQ(od.Find(0x1200, 0)->access, Access::kConst);
  EXPECT_EQ(od.Find(0x1200, 1)->access, Access::kRo);
  EXPECT_EQ(od.Find(0x1200, 1)->type, DataType::kUnsigned32);
  EXPECT_EQ(DecodeUnsignedLe(od.Find(0x1200, 1)->DefaultFor(3)), 0x603u);
  EXPECT_EQ(DecodeUnsignedLe(od.Find(0x1200, 2)->DefaultFor(3)), 0x583u);
}

}  // namespace
}  // namespace canfleet::canopen
