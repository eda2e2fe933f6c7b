// SDO server, block download and block upload: CiA 301 v4.2 §7.2.4.3.8–15 (protocols),
// §7.2.4.3.13 (protocol switch threshold), §7.2.4.3.16 (CRC), §7.2.4.3.17 (05040002/3/4).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "tests/unit/sdo/sdo_test_bench.hpp"

namespace canfleet::canopen {
namespace {

using namespace std::chrono_literals;
using test::ServerBench;
using Frames = std::vector<std::string>;

Bytes Sequence(std::size_t n) {
  Bytes out(n);
  for (std::size_t i = 0; i < n; ++i)
    out[i] = static_cast<std::uint8_t>(i);
  return out;
}

// ---- block download ----------------------------------------------------------------------------

TEST(SdoBlockDownload, WithCrcAndSize) {
  ServerBench b;
  b.probe.Send("605#C60420000A000000");               // cc = 1, s = 1, 10 bytes
  EXPECT_EQ(b.probe.Next(), "585#A40420007F000000");  // sc = 1, blksize 127
  b.probe.Send("605#0130313233343536");
  EXPECT_EQ(b.probe.Count(), 0u);        // segments are not confirmed one by one
  b.probe.Send("605#8237383900000000");  // c = 1, seqno 2
  EXPECT_EQ(b.probe.Next(), "585#A2027F0000000000");
  EXPECT_TRUE(b.od.Find(0x2004, 0)->value.empty());
  b.probe.Send("605#D1589C0000000000");  // n = 4, CRC("0123456789") = 9C58h
  EXPECT_EQ(b.probe.Next(), "585#A100000000000000");
  EXPECT_EQ(b.od.Find(0x2004, 0)->value, ToBytes("0123456789"));
  EXPECT_FALSE(b.server.Busy());
}

TEST(SdoBlockDownload, WithoutCrcTheCrcFieldIsIgnored) {
  ServerBench b;
  b.probe.Send("605#C20420000A000000");  // cc = 0
  EXPECT_EQ(b.probe.Next(), "585#A40420007F000000");
  b.probe.Send("605#0130313233343536");
  b.probe.Send("605#8237383900000000");
  EXPECT_EQ(b.probe.Next(), "585#A2027F0000000000");
  b.probe.Send("605#D1FFFF0000000000");
  EXPECT_EQ(b.probe.Next(), "585#A100000000000000");
  EXPECT_EQ(b.od.Find(0x2004, 0)->value, ToBytes("0123456789"));
}

TEST(SdoBlockDownload, WrongCrcAborts) {
  ServerBench b;
  b.probe.Send("605#C60420000A000000");
  b.probe.Send("605#0130313233343536");
  b.probe.Send("605#8237383900000000");
  b.probe.Clear();
  b.probe.Send("605#D1599C0000000000");
  EXPECT_EQ(b.probe.Next(), "585#8004200004000405");  // 05040004
  EXPECT_TRUE(b.od.Find(0x2004, 0)->value.empty());
}

TEST(SdoBlockDownload, LostSegmentIsResentFromAckseq) {
  // Server blksize 4, 35 bytes = 5 segments. Segment 2 is lost: the server acknowledges 1 at the
  // end of the sub-block and the client resends from the second segment's data.
  ServerBench b(SdoServerOptions{.block_size = 4});
  b.probe.Send("605#C604200023000000");
  EXPECT_EQ(b.probe.Next(), "585#A404200004000000");
  b.probe.Send("605#0100010203040506");
  b.probe.Send("605#030E0F1011121314");  // out of sequence: dropped
  b.probe.Send("605#0415161718191A1B");  // seqno = blksize: acknowledge
  EXPECT_EQ(b.probe.Next(), "585#A201040000000000");
  b.probe.Send("605#010708090A0B0C0D");
  b.probe.Send("605#020E0F1011121314");
  b.probe.Send("605#0315161718191A1B");
  b.probe.Send("605#841C1D1E1F202122");
  EXPECT_EQ(b.probe.Next(), "585#A204040000000000");
  b.probe.Send("605#C13ABF0000000000");  // n = 0, CRC = BF3Ah
  EXPECT_EQ(b.probe.Next(), "585#A100000000000000");
  EXPECT_EQ(b.od.Find(0x2004, 0)->value, Sequence(35));
}

TEST(SdoBlockDownload, LostLastSegmentOfASubBlockIsAcknowledgedAfterAStall) {
  // Without the segment that ends the sub-block the server would wait forever; after 70 % of the
  // SDO timeout it acknowledges what it has (CANopenNode's sub-block timeout).
  ServerBench b(SdoServerOptions{.block_size = 4});
  b.probe.Send("605#C604200023000000");
  b.probe.Send("605#0100010203040506");
  b.probe.Send("605#020708090A0B0C0D");
  b.probe.Send("605#030E0F1011121314");
  b.probe.Clear();  // segment 4 is lost
  b.scheduler.Advance(699ms);
  EXPECT_EQ(b.probe.Count(), 0u);
  b.scheduler.Advance(1ms);
  EXPECT_EQ(b.probe.Next(), "585#A203040000000000");
  b.probe.Send("605#0115161718191A1B");
  b.probe.Send("605#821C1D1E1F202122");
  EXPECT_EQ(b.probe.Next(), "585#A202040000000000");
  b.probe.Send("605#C13ABF0000000000");
  EXPECT_EQ(b.probe.Next(), "585#A100000000000000");
  EXPECT_EQ(b.od.Find(0x2004, 0)->value, Sequence(35));
}

TEST(SdoBlockDownload, StalledSubBlockStillTimesOut) {
  ServerBench b;
  b.probe.Send("605#C60420000A000000");
  b.probe.Clear();
  b.scheduler.Advance(700ms);
  EXPECT_EQ(b.probe.Next(), "585#A2007F0000000000");  // ackseq 0: resend everything
  b.scheduler.Advance(300ms);
  EXPECT_EQ(b.probe.Next(), "585#8004200000000405");
}

TEST(SdoBlockDownload, DuplicateSegmentsAreIgnored) {
  ServerBench b;
  b.probe.Send("605#C60420000A000000");
  b.probe.Send("605#0130313233343536");
  b.probe.Send("605#0130313233343536");
  b.probe.Send("605#8237383900000000");
  b.probe.Send("605#D1589C0000000000");
  EXPECT_EQ(b.probe.Take(), (Frames{"585#A40420007F000000", "585#A2027F0000000000", "585#A100000000000000"}));
  EXPECT_EQ(b.od.Find(0x2004, 0)->value, ToBytes("0123456789"));
}

TEST(SdoBlockDownload, SeqnoZeroOrAboveBlksizeAborts) {
  ServerBench b(SdoServerOptions{.block_size = 4});
  b.probe.Send("605#C60420000A000000");
  b.probe.Clear();
  b.probe.Send("605#0030313233343536");
  EXPECT_EQ(b.probe.Next(), "585#8004200003000405");  // 05040003
  b.probe.Send("605#C60420000A000000");
  b.probe.Clear();
  b.probe.Send("605#0530313233343536");
  EXPECT_EQ(b.probe.Next(), "585#8004200003000405");
}

TEST(SdoBlockDownload, TotalDifferentFromIndicatedSizeAborts) {
  ServerBench b;
  b.probe.Send("605#C204200003000000");
  b.probe.Send("605#8101020304050607");
  b.probe.Clear();
  b.probe.Send("605#C100000000000000");  // 7 bytes, 3 indicated
  EXPECT_EQ(b.probe.Next(), "585#8004200010000706");
}

TEST(SdoBlockDownload, FixedSizeObjectChecksTheLengthAtTheEnd) {
  ServerBench b;
  b.probe.Send("605#C001200000000000");  // no size, no CRC
  b.probe.Send("605#8101020000000000");
  b.probe.Clear();
  b.probe.Send("605#D500000000000000");  // n = 5: two bytes for a U32
  EXPECT_EQ(b.probe.Next(), "585#8001200013000706");
}

TEST(SdoBlockDownload, DataBeyondTheLimitWithoutSizeIsOutOfMemory) {
  ServerBench b(SdoServerOptions{.max_transfer_bytes = 16});
  b.probe.Send("605#C004200000000000");
  b.probe.Send("605#0101020304050607");
  b.probe.Send("605#0201020304050607");
  b.probe.Send("605#0301020304050607");
  b.probe.Clear();
  b.probe.Send("605#0401020304050607");  // 28 bytes buffered
  EXPECT_EQ(b.probe.Next(), "585#8004200005000405");
}

TEST(SdoBlockDownload, InsideASubBlockEveryFrameButAbortIsASegment) {
  ServerBench b;
  b.probe.Send("605#C60420000A000000");
  b.probe.Clear();
  b.probe.Send("605#4000100000000000");  // seqno 64, out of sequence: dropped, not an upload
  EXPECT_EQ(b.probe.Count(), 0u);
  b.probe.Send("605#8000000000000000");  // the client's abort
  EXPECT_FALSE(b.server.Busy());
  EXPECT_EQ(b.probe.Count(), 0u);
  b.probe.Send("605#4000100000000000");
  EXPECT_EQ(b.probe.Next(), "585#4300100094010F00");
}

// ---- block upload ------------------------------------------------------------------------------

TEST(SdoBlockUpload, WithCrc) {
  ServerBench b;
  b.probe.Send("605#A40810007F000000");               // cc = 1, blksize 127, pst 0
  EXPECT_EQ(b.probe.Next(), "585#C60810000F000000");  // sc = 1, s = 1, 15 bytes
  b.probe.Send("605#A300000000000000");
  EXPECT_EQ(b.probe.Take(), (Frames{"585#0163616E666C6565", "585#0274207365727665", "585#8372000000000000"}));
  b.probe.Send("605#A2037F0000000000");
  EXPECT_EQ(b.probe.Next(), "585#D949C60000000000");  // n = 6, CRC("canfleet server") = C649h
  b.probe.Send("605#A100000000000000");
  EXPECT_EQ(b.probe.Count(), 0u);
  EXPECT_FALSE(b.server.Busy());
}

TEST(SdoBlockUpload, WithoutCrcTheEndCarriesZero) {
  ServerBench b;
  b.probe.Send("605#A00810007F000000");
  EXPECT_EQ(b.probe.Next(), "585#C60810000F000000");
  b.probe.Send("605#A300000000000000");
  b.probe.Clear();
  b.probe.Send("605#A2037F0000000000");
  EXPECT_EQ(b.probe.Next(), "585#D900000000000000");
}

TEST(SdoBlockUpload, HonoursTheClientsBlksize) {
  ServerBench b;
  b.probe.Send("605#A408100002000000");  // blksize 2
  b.probe.Send("605#A300000000000000");
  EXPECT_EQ(b.probe.Take(), (Frames{"585#C60810000F000000", "585#0163616E666C6565", "585#0274207365727665"}));
  b.probe.Send("605#A202020000000000");
  EXPECT_EQ(b.probe.Take(), (Frames{"585#8172000000000000"}));
  b.probe.Send("605#A201020000000000");
  EXPECT_EQ(b.probe.Next(), "585#D949C60000000000");
}

TEST(SdoBlockUpload, ResendsAfterTheClientsAckseq) {
  ServerBench b;
  b.probe.Send("605#A40810007F000000");
  b.probe.Send("605#A300000000000000");
  b.probe.Clear();
  b.probe.Send("605#A2017F0000000000");  // segment 2 was lost
  EXPECT_EQ(b.probe.Take(), (Frames{"585#0174207365727665", "585#8272000000000000"}));
  b.probe.Send("605#A2027F0000000000");
  EXPECT_EQ(b.probe.Next(), "585#D949C60000000000");
}

TEST(SdoBlockUpload, EmptyValueIsOneEmptySegment) {
  ServerBench b;
  b.probe.Send("605#A40420007F000000");
  b.probe.Send("605#A300000000000000");
  EXPECT_EQ(b.probe.Take(), (Frames{"585#C604200000000000", "585#8100000000000000"}));
  b.probe.Send("605#A2017F0000000000");
  EXPECT_EQ(b.probe.Next(), "585#DD00000000000000");  // n = 7, CRC of nothing = 0
}

TEST(SdoBlockUpload, AckOfUnsentSegmentAborts) {
  ServerBench b;
  b.probe.Send("605#A40810007F000000");
  b.probe.Send("605#A300000000000000");
  b.probe.Clear();
  b.probe.Send("605#A2047F0000000000");  // only 3 were sent
  EXPECT_EQ(b.probe.Next(), "585#8008100003000405");
}

TEST(SdoBlockUpload, InvalidBlksizeInAckAborts) {
  ServerBench b;
  b.probe.Send("605#A408100002000000");
  b.probe.Send("605#A300000000000000");
  b.probe.Clear();
  b.probe.Send("605#A202000000000000");
  EXPECT_EQ(b.probe.Next(), "585#8008100002000405");
  b.probe.Send("605#A408100002000000");
  b.probe.Send("605#A300000000000000");
  b.probe.Clear();
  b.probe.Send("605#A202800000000000");
  EXPECT_EQ(b.probe.Next(), "585#8008100002000405");
}

// ---- protocol switch threshold (§7.2.4.3.13) ---------------------------------------------------

TEST(SdoBlockUpload, AtOrBelowPstTheServerAnswersWithANormalUpload) {
  ServerBench b;
  b.probe.Send("605#A40010007F040000");  // pst 4, 1000h has 4 bytes
  EXPECT_EQ(b.probe.Next(), "585#4300100094010F00");
  EXPECT_FALSE(b.server.Busy());
  b.probe.Send("605#A40810007F0F0000");  // pst 15, 1008h has 15 bytes: segmented
  EXPECT_EQ(b.probe.Next(), "585#410810000F000000");
  b.probe.Send("605#6000000000000000");
  EXPECT_EQ(b.probe.Next(), "585#0063616E666C6565");
}

TEST(SdoBlockUpload, AbovePstTheTransferIsABlockUpload) {
  ServerBench b;
  b.probe.Send("605#A40810007F0E0000");  // pst 14 < 15 bytes
  EXPECT_EQ(b.probe.Next(), "585#C60810000F000000");
}

}  // namespace
}  // namespace canfleet::canopen
