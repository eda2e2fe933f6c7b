#include "bus/capture/pcap_writer.hpp"

#include <gtest/gtest.h>

#include <system_error>
#include <vector>

#include "tests/support/bus_probe.hpp"
#include "tests/unit/capture/capture_test_support.hpp"

namespace canfleet::capture {
namespace {

using canfleet::test::Frame;
using test::At;
using Bytes = std::vector<std::uint8_t>;

template <std::size_t N>
Bytes ToVector(const std::array<std::uint8_t, N>& a) {
  return {a.begin(), a.end()};
}

// pcap file format (https://www.tcpdump.org/manpages/pcap-savefile.5.txt), little-endian.
TEST(Pcap, GlobalHeaderDeclaresLinktypeCanSocketcan) {
  const Bytes expected = {
      0xD4, 0xC3, 0xB2, 0xA1,  // magic: microsecond timestamps
      0x02, 0x00, 0x04, 0x00,  // version 2.4
      0x00, 0x00, 0x00, 0x00,  // thiszone
      0x00, 0x00, 0x00, 0x00,  // sigfigs
      0xFF, 0xFF, 0x00, 0x00,  // snaplen 65535
      0xE3, 0x00, 0x00, 0x00,  // LINKTYPE_CAN_SOCKETCAN = 227
  };
  EXPECT_EQ(ToVector(PcapGlobalHeader()), expected);
}

// LINKTYPE_CAN_SOCKETCAN: CAN id + flags big-endian, length, FD flags, 2 reserved, 8 data bytes.
TEST(Pcap, StandardDataFrame) {
  const Bytes expected = {
      0x00, 0xF1, 0x53, 0x65,  // ts_sec 1700000000
      0x40, 0xE2, 0x01, 0x00,  // ts_usec 123456
      0x10, 0x00, 0x00, 0x00,  // incl_len 16
      0x10, 0x00, 0x00, 0x00,  // orig_len 16
      0x00, 0x00, 0x01, 0x23,  // can_id 0x123, network byte order
      0x04, 0x00, 0x00, 0x00,  // len 4, FD flags, reserved
      0xDE, 0xAD, 0xBE, 0xEF, 0x00, 0x00, 0x00, 0x00,
  };
  EXPECT_EQ(ToVector(PcapRecord(Frame("123#DEADBEEF"), At(1700000000, 123456))), expected);
}

TEST(Pcap, ExtendedFrameSetsCanEffFlag) {
  const Bytes record = ToVector(PcapRecord(Frame("1ABCDEF0#0011223344556677"), At(1700000000)));
  const Bytes frame(record.begin() + 16, record.end());
  const Bytes expected = {0x9A, 0xBC, 0xDE, 0xF0,  // 0x80000000 | 0x1ABCDEF0
                          0x08, 0x00, 0x00, 0x00, 0x00, 0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77};
  EXPECT_EQ(frame, expected);
}

TEST(Pcap, RemoteFrameSetsCanRtrFlagAndKeepsItsDlc) {
  const Bytes record = ToVector(PcapRecord(CanFrame::Remote(0x705, 1), At(1700000000)));
  const Bytes frame(record.begin() + 16, record.end());
  const Bytes expected = {0x40, 0x00, 0x07, 0x05, 0x01, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
  EXPECT_EQ(frame, expected);
}

TEST(Pcap, ErrorFrameSetsCanErrFlag) {
  CanFrame failed;
  failed.id = 0x181;
  failed.flags = CanFrame::kError;
  const Bytes record = ToVector(PcapRecord(failed, At(1700000000)));
  const Bytes frame(record.begin() + 16, record.end());
  const Bytes expected = {0x20, 0x00, 0x00, 0x88, 0x08, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
  EXPECT_EQ(frame, expected);
}

TEST(Pcap, BytesBeyondTheDlcAreZero) {
  CanFrame f = Frame("123#AA");
  f.data[5] = 0x55;  // not part of the frame
  const Bytes record = ToVector(PcapRecord(f, At(0)));
  EXPECT_EQ(record[16 + 8], 0xAA);
  EXPECT_EQ(record[16 + 13], 0x00);
}

TEST(Pcap, WriterProducesHeaderThenRecords) {
  test::TempPath file("can0.pcap");
  {
    PcapWriter writer(file.path());
    writer.Write(Frame("123#DEADBEEF"), At(1700000000, 1));
    writer.Write(CanFrame::Remote(0x705, 0), At(1700000000, 2));
    EXPECT_TRUE(test::ReadBytes(file.path()).empty()) << "writes are buffered";
    writer.Close();
    EXPECT_TRUE(writer.ok());
  }
  Bytes expected = ToVector(PcapGlobalHeader());
  for (const auto& r : {PcapRecord(Frame("123#DEADBEEF"), At(1700000000, 1)),
                        PcapRecord(CanFrame::Remote(0x705, 0), At(1700000000, 2))})
    expected.insert(expected.end(), r.begin(), r.end());
  EXPECT_EQ(test::ReadBytes(file.path()), expected);
}

TEST(Pcap, UnwritableFileThrowsAtOpen) {
  EXPECT_THROW(PcapWriter("/nonexistent-dir/x.pcap"), std::system_error);
}

}  // namespace
}  // namespace canfleet::capture
