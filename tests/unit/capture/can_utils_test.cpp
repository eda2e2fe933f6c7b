// Our candump logs read back with can-utils' own parser (lib.c parse_canframe, the one canplayer
// uses): log2long prints each frame of a log in long form.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "bus/capture/candump_log.hpp"
#include "tests/support/bus_probe.hpp"
#include "tests/unit/capture/capture_test_support.hpp"

namespace canfleet::capture {
namespace {

using canfleet::test::Frame;
using test::At;

TEST(CanUtils, Log2longReadsOurCandumpLog) {
  if (std::system("command -v log2long >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "log2long (can-utils) is not installed: apt-get install can-utils";
  test::TempPath file("can0.log");
  CanFrame failed;
  failed.id = 0x181;
  failed.flags = CanFrame::kError;
  {
    CandumpLogWriter writer(file.path(), "can0");
    writer.Write(Frame("123#DEADBEEF"), At(1700000000, 123456));
    writer.Write(Frame("1ABCDEF0#0011223344556677"), At(1700000000, 123457));
    writer.Write(CanFrame::Remote(0x705, 1), At(1700000000, 123458));
    writer.Write(failed, At(1700000000, 123459));
  }
  std::string out;
  FILE* pipe = ::popen(("log2long < " + file.path().string()).c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  char buf[512];
  while (std::fgets(buf, sizeof buf, pipe) != nullptr)
    out += buf;
  ASSERT_EQ(::pclose(pipe), 0);
  EXPECT_EQ(out,
            "(1700000000.123456)  can0       123   [4]  DE AD BE EF               '....'\n"
            "(1700000000.123457)  can0  1ABCDEF0   [8]  00 11 22 33 44 55 66 77   '..\"3DUfw'\n"
            "(1700000000.123458)  can0       705   [1]  remote request\n"
            "(1700000000.123459)  can0  20000088   [8]  00 00 00 00 00 00 00 00   ERRORFRAME\n");
}

}  // namespace
}  // namespace canfleet::capture
