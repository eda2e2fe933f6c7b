#include "bus/capture/candump_log.hpp"

#include <gtest/gtest.h>

#include <system_error>

#include "tests/support/bus_probe.hpp"
#include "tests/unit/capture/capture_test_support.hpp"

namespace canfleet::capture {
namespace {

using canfleet::test::Frame;
using test::At;

// The lines `candump -l` writes (can-utils candump.c: "(%010lld.%06ld) %s %s\n" with lib.c's
// snprintf_canframe), which canplayer reads back.
TEST(CandumpLog, DataFramesAsCandumpWritesThem) {
  EXPECT_EQ(CandumpLogLine(Frame("123#DEADBEEF"), At(1700000000, 123456), "can0"),
            "(1700000000.123456) can0 123#DEADBEEF\n");
  EXPECT_EQ(CandumpLogLine(Frame("7FF#"), At(1700000000), "can1"), "(1700000000.000000) can1 7FF#\n");
  EXPECT_EQ(CandumpLogLine(Frame("000#0001020304050607"), At(1700000001, 999999), "can0"),
            "(1700000001.999999) can0 000#0001020304050607\n");
}

TEST(CandumpLog, ExtendedIdentifiersHaveEightDigits) {
  EXPECT_EQ(CandumpLogLine(Frame("1ABCDEF0#00FF"), At(1700000000, 5), "can0"),
            "(1700000000.000005) can0 1ABCDEF0#00FF\n");
  CanFrame small = CanFrame::Data(0x123, {0x11});
  small.flags |= CanFrame::kExtended;  // a 29-bit id with a small value keeps its 8 digits
  EXPECT_EQ(CandumpLogLine(small, At(1700000000), "can0"), "(1700000000.000000) can0 00000123#11\n");
}

TEST(CandumpLog, RemoteFramesCarryTheirDlcWhenNotZero) {
  // lib.c: 'R', then the DLC of a remote frame if it is not zero.
  EXPECT_EQ(CandumpLogLine(CanFrame::Remote(0x705, 0), At(1700000000), "can0"),
            "(1700000000.000000) can0 705#R\n");
  EXPECT_EQ(CandumpLogLine(CanFrame::Remote(0x705, 1), At(1700000000), "can0"),
            "(1700000000.000000) can0 705#R1\n");
  CanFrame ext = CanFrame::Remote(0x1FFFFFFF, 8);
  ext.flags |= CanFrame::kExtended;
  EXPECT_EQ(CandumpLogLine(ext, At(1700000000), "can0"), "(1700000000.000000) can0 1FFFFFFF#R8\n");
}

TEST(CandumpLog, ErrorFramesAreSocketCanErrorFrames) {
  // The broker's form (failed transfer, DLC 0): CAN_ERR_FLAG | CAN_ERR_PROT | CAN_ERR_BUSERROR.
  CanFrame failed;
  failed.id = 0x181;
  failed.flags = CanFrame::kError;
  EXPECT_EQ(CandumpLogLine(failed, At(1700000000), "can0"),
            "(1700000000.000000) can0 20000088#0000000000000000\n");
  // The SocketCAN form (class bits and detail bytes, DLC 8) is kept: CAN_ERR_BUSOFF here.
  CanFrame bus_off;
  bus_off.id = 0x40;
  bus_off.dlc = 8;
  bus_off.flags = CanFrame::kError;
  bus_off.data = {0, 0, 0, 0, 0, 0, 0x80, 0};
  EXPECT_EQ(CandumpLogLine(bus_off, At(1700000000), "can0"),
            "(1700000000.000000) can0 20000040#0000000000008000\n");
}

TEST(CandumpLog, TimesAreTruncatedToMicrosecondsAndPadded) {
  const WallTime t = At(1700000000, 123456) + std::chrono::nanoseconds(999);
  EXPECT_EQ(CandumpLogLine(Frame("001#"), t, "can0"), "(1700000000.123456) can0 001#\n");
  EXPECT_EQ(CandumpLogLine(Frame("001#"), At(12, 34), "can0"), "(0000000012.000034) can0 001#\n");
  EXPECT_EQ(CandumpLogLine(Frame("001#"), At(-5), "can0"), "(0000000000.000000) can0 001#\n");
}

TEST(CandumpLog, WriterBuffersUntilFlushAndClose) {
  test::TempPath file("can0.log");
  CandumpLogWriter writer(file.path(), "can0");
  writer.Write(Frame("123#DEADBEEF"), At(1700000000, 1));
  writer.Write(Frame("1ABCDEF0#01"), At(1700000000, 2));
  EXPECT_EQ(test::ReadText(file.path()), "") << "writes are buffered";
  writer.Flush();
  EXPECT_EQ(test::ReadText(file.path()),
            "(1700000000.000001) can0 123#DEADBEEF\n"
            "(1700000000.000002) can0 1ABCDEF0#01\n");
  writer.Write(CanFrame::Remote(0x705, 1), At(1700000000, 3));
  writer.Close();
  writer.Write(Frame("7FF#FF"), At(1700000000, 4));  // ignored after Close
  writer.Close();
  EXPECT_TRUE(writer.ok());
  EXPECT_EQ(test::ReadText(file.path()),
            "(1700000000.000001) can0 123#DEADBEEF\n"
            "(1700000000.000002) can0 1ABCDEF0#01\n"
            "(1700000000.000003) can0 705#R1\n");
}

TEST(CandumpLog, DestructorFlushes) {
  test::TempPath file("can0.log");
  {
    CandumpLogWriter writer(file.path(), "vcan0");
    writer.Write(Frame("080#"), At(1700000000));
  }
  EXPECT_EQ(test::ReadText(file.path()), "(1700000000.000000) vcan0 080#\n");
}

TEST(CandumpLog, LargeCapturesGoOutInBlocks) {
  test::TempPath file("big.log");
  CandumpLogWriter writer(file.path(), "can0");
  std::string expected;
  for (int i = 0; i < 5000; ++i) {
    const CanFrame f = CanFrame::Data(static_cast<std::uint32_t>(i % 0x800), {static_cast<std::uint8_t>(i)});
    writer.Write(f, At(1700000000, i));
    expected += CandumpLogLine(f, At(1700000000, i), "can0");
  }
  EXPECT_GT(test::ReadText(file.path()).size(), 0u) << "a full buffer is written before Flush";
  writer.Close();
  EXPECT_EQ(test::ReadText(file.path()), expected);
}

TEST(CandumpLog, UnwritableFileThrowsAtOpen) {
  EXPECT_THROW(CandumpLogWriter("/nonexistent-dir/x.log", "can0"), std::system_error);
}

TEST(CandumpLog, WriteFailureIsReportedNotThrown) {
  if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "/dev/full is not available";
  CandumpLogWriter writer("/dev/full", "can0");  // every write fails with ENOSPC
  writer.Write(Frame("123#01"), At(1700000000));
  EXPECT_TRUE(writer.ok());
  writer.Flush();
  EXPECT_FALSE(writer.ok());
  EXPECT_NE(writer.error().find("/dev/full"), std::string::npos) << writer.error();
  writer.Write(Frame("123#02"), At(1700000000));  // ignored, no crash
  writer.Close();
}

}  // namespace
}  // namespace canfleet::capture
