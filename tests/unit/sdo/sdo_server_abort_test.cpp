// Every abort code of CiA 301 v4.2 §7.2.4.3.17 (table 22) the server can give, each with its exact
// frame: 585h | 80 | index (LE16) | sub-index | code (LE32).
#include <gtest/gtest.h>

#include <ostream>
#include <string>
#include <vector>

#include "tests/unit/sdo/sdo_test_bench.hpp"

namespace canfleet::canopen {
namespace {

using namespace std::chrono_literals;
using test::ServerBench;

struct AbortCase {
  std::string name;
  std::vector<std::string> setup;  ///< requests sent first; their responses are not checked
  std::string request;
  std::string abort;  ///< the expected response
  SdoAbort veto = SdoAbort::kNone;
};

void PrintTo(const AbortCase& c, std::ostream* os) {
  *os << c.name;
}

std::string AbortCaseName(const ::testing::TestParamInfo<AbortCase>& param_info) {
  return param_info.param.name;
}

class SdoAbortTest : public ::testing::TestWithParam<AbortCase> {};

TEST_P(SdoAbortTest, AbortsWithTheExactFrame) {
  const AbortCase& c = GetParam();
  ServerBench b;
  b.veto = c.veto;
  for (const auto& frame : c.setup)
    b.probe.Send(frame);
  b.probe.Clear();
  b.probe.Send(c.request);
  EXPECT_EQ(b.probe.Next(), c.abort);
  EXPECT_EQ(b.probe.Count(), 0u);
  EXPECT_FALSE(b.server.Busy());
  // Not wedged: the next valid request is served.
  b.probe.Send("605#4000100000000000");
  EXPECT_EQ(b.probe.Next(), "585#4300100094010F00");
}

INSTANTIATE_TEST_SUITE_P(
    AbortCodes, SdoAbortTest,
    ::testing::Values(
        // 06020000 object does not exist; 06090011 sub-index does not exist (OD Lookup).
        AbortCase{"NoObjectUpload", {}, "605#4000300000000000", "585#8000300000000206"},
        AbortCase{"NoObjectDownload", {}, "605#2300300001000000", "585#8000300000000206"},
        AbortCase{"NoObjectBlockUpload", {}, "605#A40030007F000000", "585#8000300000000206"},
        AbortCase{"NoSubIndexUpload", {}, "605#4010200200000000", "585#8010200211000906"},
        AbortCase{"NoSubIndexSegmented", {}, "605#2110200201000000", "585#8010200211000906"},
        // 06010001 read of a write-only object; 06010002 write of a read-only/const object.
        AbortCase{"WriteOnly", {}, "605#4002200000000000", "585#8002200001000106"},
        AbortCase{"ReadOnlyExpedited", {}, "605#2300100001000000", "585#8000100002000106"},
        AbortCase{"ConstSegmented", {}, "605#2108100004000000", "585#8008100002000106"},
        AbortCase{"ReadOnlyBlock", {}, "605#C600100004000000", "585#8000100002000106"},
        // 06070012 / 06070013: indicated size vs the object's fixed size.
        AbortCase{"TooHighExpedited", {}, "605#2B00200001020000", "585#8000200012000706"},
        AbortCase{"TooLowExpedited", {}, "605#2F17100001000000", "585#8017100013000706"},
        AbortCase{"TooHighSegmentedInitiate", {}, "605#2101200005000000", "585#8001200012000706"},
        AbortCase{"TooLowSegmentedInitiate", {}, "605#2101200003000000", "585#8001200013000706"},
        AbortCase{"TooHighBlockInitiate", {}, "605#C601200005000000", "585#8001200012000706"},
        AbortCase{"TooLowWithoutSizeAtTheEnd",
                  {"605#2001200000000000"},
                  "605#0B01020300000000",
                  "585#8001200013000706"},
        // 06070010: the segmented total differs from the indicated size.
        AbortCase{"SegmentedTotalTooLong",
                  {"605#2104200003000000"},
                  "605#0101020304050607",
                  "585#8004200010000706"},
        AbortCase{"SegmentedTotalTooShort",
                  {"605#210420000A000000"},
                  "605#0B01020300000000",
                  "585#8004200010000706"},
        // 06090030/31/32 from the OD's value checks.
        AbortCase{"InvalidValue", {}, "605#2F05200002000000", "585#8005200030000906"},
        AbortCase{"ValueTooHigh", {}, "605#2301200001040000", "585#8001200031000906"},
        AbortCase{"ValueTooLow", {}, "605#2301200005000000", "585#8001200032000906"},
        // 08000020/21/22 and 06090030 passed through from a validator; 08000024 from a read hook.
        AbortCase{
            "CannotTransfer", {}, "605#2B03200001000000", "585#8003200020000008", SdoAbort::kCannotTransfer},
        AbortCase{
            "LocalControl", {}, "605#2B03200001000000", "585#8003200021000008", SdoAbort::kLocalControl},
        AbortCase{"DeviceState", {}, "605#2B03200001000000", "585#8003200022000008", SdoAbort::kDeviceState},
        AbortCase{"ValidatorInvalidValue",
                  {"605#2103200002000000"},
                  "605#0B01000000000000",
                  "585#8003200030000906",
                  SdoAbort::kInvalidValue},
        AbortCase{"NoData", {}, "605#4011200000000000", "585#8011200024000008"},
        // 05040001: unknown command specifier, or one with no transfer to belong to (index 0).
        AbortCase{"UnknownSpecifier", {}, "605#E000000000000000", "585#8000000001000405"},
        AbortCase{"SegmentWithoutTransfer", {}, "605#0001020304050607", "585#8000000001000405"},
        AbortCase{"UploadSegmentWithoutTransfer", {}, "605#6000000000000000", "585#8000000001000405"},
        AbortCase{"BlockEndWithoutTransfer", {}, "605#C100000000000000", "585#8000000001000405"},
        AbortCase{"BlockAckWithoutTransfer", {}, "605#A2017F0000000000", "585#8000000001000405"},
        AbortCase{"BlockStartWithoutTransfer", {}, "605#A300000000000000", "585#8000000001000405"},
        AbortCase{"WrongSpecifierInTransfer",
                  {"605#2104200003000000"},
                  "605#6000000000000000",
                  "585#8004200001000405"},
        AbortCase{
            "BlockAckBeforeStart", {"605#A40810007F000000"}, "605#A2007F0000000000", "585#8008100001000405"},
        // 05030000: toggle bit not alternated.
        AbortCase{"ToggleDownload", {"605#210420000A000000"}, "605#1030313233343536", "585#8004200000000305"},
        AbortCase{"ToggleDownloadSecond",
                  {"605#210420000A000000", "605#0030313233343536"},
                  "605#0937383900000000",
                  "585#8004200000000305"},
        AbortCase{"ToggleUpload", {"605#4008100000000000"}, "605#7000000000000000", "585#8008100000000305"},
        // 05040005: indicated size above max_transfer_bytes (1 MiB by default).
        AbortCase{"OutOfMemorySegmented", {}, "605#2104200001001000", "585#8004200005000405"},
        AbortCase{"OutOfMemoryBlock", {}, "605#C604200001001000", "585#8004200005000405"},
        // 05040002: block size 0 or above 127.
        AbortCase{"BlockSizeZero", {}, "605#A404200000000000", "585#8004200002000405"},
        AbortCase{"BlockSize128", {}, "605#A404200080000000", "585#8004200002000405"}),
    AbortCaseName);

TEST(SdoServerAbort, DownloadWithoutSizeBeyondTheLimitIsOutOfMemory) {
  ServerBench b(SdoServerOptions{.timeout = 1s, .max_transfer_bytes = 16});
  b.probe.Send("605#2004200000000000");
  b.probe.Send("605#0001020304050607");
  b.probe.Send("605#1001020304050607");
  EXPECT_EQ(b.probe.Take(), (std::vector<std::string>{"585#6004200000000000", "585#2000000000000000",
                                                      "585#3000000000000000"}));
  b.probe.Send("605#0001020304050607");  // 21 > 16 bytes
  EXPECT_EQ(b.probe.Next(), "585#8004200005000405");
}

TEST(SdoServerAbort, TimeoutAbortsAfterTheConfiguredTime) {
  // §7.2.4.3.17 05040000; measured from the client's last frame.
  ServerBench b;
  b.probe.Send("605#210420000A000000");
  b.scheduler.Advance(600ms);
  b.probe.Send("605#0030313233343536");
  b.probe.Clear();
  b.scheduler.Advance(999ms);
  EXPECT_EQ(b.probe.Count(), 0u);
  b.scheduler.Advance(1ms);
  EXPECT_EQ(b.probe.Next(), "585#8004200000000405");
  EXPECT_FALSE(b.server.Busy());
  EXPECT_TRUE(b.od.Find(0x2004, 0)->value.empty());
  b.probe.Send("605#1937383900000000");  // too late: no transfer any more
  EXPECT_EQ(b.probe.Next(), "585#8000000001000405");
}

TEST(SdoServerAbort, TimeoutInEachWaitingState) {
  const std::vector<std::vector<std::string>> starts = {
      {"605#4008100000000000"},                                                  // segmented upload
      {"605#C604200003000000"},                                                  // block download, sub-block
      {"605#C604200003000000", "605#8101020300000000"},                          // block download, end
      {"605#A40810007F000000"},                                                  // block upload, before start
      {"605#A40810007F000000", "605#A300000000000000"},                          // block upload, sub-block
      {"605#A40810007F000000", "605#A300000000000000", "605#A2037F0000000000"},  // block upload end
  };
  for (const auto& script : starts) {
    ServerBench b;
    for (const auto& frame : script)
      b.probe.Send(frame);
    ASSERT_TRUE(b.server.Busy()) << script.back();
    b.scheduler.Advance(2s);
    const auto frames = b.probe.Take();
    ASSERT_FALSE(frames.empty());
    EXPECT_EQ(frames.back().substr(0, 6), "585#80") << script.back();
    EXPECT_EQ(frames.back().substr(12), "00000405") << script.back();
    EXPECT_FALSE(b.server.Busy());
  }
}

TEST(SdoServerAbort, NoTimeoutWhenDisabledByOptions) {
  ServerBench b(SdoServerOptions{.timeout = Duration::zero()});
  b.probe.Send("605#4008100000000000");
  b.probe.Clear();
  b.scheduler.Advance(1h);
  EXPECT_EQ(b.probe.Count(), 0u);
  EXPECT_TRUE(b.server.Busy());
}

}  // namespace
}  // namespace canfleet::canopen
