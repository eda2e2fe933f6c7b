// Our pcap files decode in Wireshark: tshark (Wireshark 4.0 on Debian 12) reads a capture with
// LINKTYPE_CAN_SOCKETCAN frames and reports the identifiers, formats, flags and bytes we wrote,
// and its CANopen dissector decodes the payload (design.md: "so Wireshark's CANopen dissector
// reads our captures").
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "bus/capture/pcap_writer.hpp"
#include "tests/support/bus_probe.hpp"
#include "tests/support/text_lines.hpp"
#include "tests/unit/capture/capture_test_support.hpp"

namespace canfleet::capture {
namespace {

using canfleet::test::Frame;
using test::At;

bool HaveTshark() {
  return std::system("command -v tshark >/dev/null 2>&1") == 0;
}

/// Runs a shell command; returns its standard output (standard error goes to `stderr_file`).
std::string RunCommand(const std::string& command, const std::filesystem::path& stderr_file, int& status) {
  std::string out;
  FILE* pipe = ::popen((command + " 2>" + stderr_file.string()).c_str(), "r");
  if (pipe == nullptr) {
    status = -1;
    return out;
  }
  std::array<char, 4096> buf{};
  std::size_t n;
  while ((n = std::fread(buf.data(), 1, buf.size(), pipe)) > 0)
    out.append(buf.data(), n);
  status = ::pclose(pipe);
  return out;
}

using ::canfleet::test::Lines;

#define SKIP_WITHOUT_TSHARK()                                                 \
  if (!HaveTshark())                                                          \
  GTEST_SKIP() << "tshark is not installed: apt-get install tshark (preseed " \
                  "wireshark-common/install-setuid false for a non-interactive install)"

TEST(Tshark, DecodesIdentifiersFlagsAndData) {
  SKIP_WITHOUT_TSHARK();
  test::TempPath file("frames.pcap");
  CanFrame small_ext = Frame("123#AABBCC");
  small_ext.flags |= CanFrame::kExtended;
  CanFrame failed;
  failed.id = 0x181;
  failed.flags = CanFrame::kError;
  {
    PcapWriter writer(file.path());
    writer.Write(Frame("123#DEADBEEF"), At(1700000000, 1));               // 11-bit, DLC 4
    writer.Write(Frame("1ABCDEF0#0011223344556677"), At(1700000000, 2));  // 29-bit, DLC 8
    writer.Write(small_ext, At(1700000000, 3));                           // 29-bit, small value
    writer.Write(CanFrame::Remote(0x705, 1), At(1700000000, 4));          // remote, DLC 1
    writer.Write(Frame("7FF#01"), At(1700000000, 5));                     // DLC 1
    writer.Write(Frame("080#"), At(1700000000, 6));                       // DLC 0 (SYNC)
    writer.Write(Frame("1FFFFFFF#0102030405"), At(1700000001, 999999));   // largest id, DLC 5
    writer.Write(failed, At(1700000002));                                 // error frame
    writer.Close();
    ASSERT_TRUE(writer.ok()) << writer.error();
  }
  int status = 0;
  const std::string out =
      RunCommand("tshark -r " + file.path().string() +
                     " -T fields -E separator=, -e frame.time_epoch -e can.id -e can.flags.xtd"
                     " -e can.flags.rtr -e can.flags.err -e can.len -e data.data",
                 file.path().string() + ".stderr", status);
  ASSERT_EQ(status, 0) << test::ReadText(file.path().string() + ".stderr");
  const std::vector<std::string> expected = {
      "1700000000.000001000,291,0,0,0,4,deadbeef",
      "1700000000.000002000,448585456,1,0,0,8,0011223344556677",
      "1700000000.000003000,291,1,0,0,3,aabbcc",
      // Wireshark shows a remote frame's DLC bytes (zero in the capture) as data.
      "1700000000.000004000,1797,0,1,0,1,00",
      "1700000000.000005000,2047,0,0,0,1,01",
      "1700000000.000006000,128,0,0,0,0,",
      "1700000001.999999000,536870911,1,0,0,5,0102030405",
      // An error frame has no identifier: CAN_ERR_FLAG with the class bits.
      "1700000002.000000000,,,,1,8,",
  };
  EXPECT_EQ(Lines(out), expected) << out;
}

TEST(Tshark, CanopenDissectorReadsOurCaptures) {
  SKIP_WITHOUT_TSHARK();
  test::TempPath file("canopen.pcap");
  {
    PcapWriter writer(file.path());
    writer.Write(Frame("605#4017100000000000"), At(1700000000, 0));  // SDO upload request 1017h:00
    writer.Write(Frame("585#4B171000E8030000"), At(1700000000, 1));  // response: 1000 ms
    writer.Write(Frame("705#05"), At(1700000000, 2));                // heartbeat: operational
  }
  int status = 0;
  const std::string out =
      RunCommand("tshark -r " + file.path().string() +
                     " -d can.subdissector,canopen -T fields -E separator=, -e can.id"
                     " -e canopen.function_code -e canopen.node_id -e canopen.sdo.main_idx"
                     " -e canopen.sdo.sub_idx",
                 file.path().string() + ".stderr", status);
  ASSERT_EQ(status, 0) << test::ReadText(file.path().string() + ".stderr");
  const std::vector<std::string> lines = Lines(out);
  ASSERT_EQ(lines.size(), 3u) << out;
  EXPECT_EQ(lines[0].substr(0, 5), "1541,") << out;
  EXPECT_NE(lines[0].find(",0x1017,"), std::string::npos) << out;
  EXPECT_NE(lines[1].find(",0x1017,"), std::string::npos) << out;
  EXPECT_EQ(lines[2].substr(0, 5), "1797,") << out;
}

}  // namespace
}  // namespace canfleet::capture
