// The generic node with an EDS somebody else wrote (issue 5: "the generic --eds node works with an
// EDS written by someone else (craft one in the CiA 306 style by hand for the test)"; design
// decision 4: "A node started with --eds any.eds and no device behaves as a generic DS-301 slave").
//
// data/brightwater-tx4.eds is a hand-written third-party file (object lists, RECORD and ARRAY
// objects, $NODEID COB-IDs, strings, limits, default PDOs). canfleet-node --eds runs it as node 9
// on a broker reached over a Unix socket; the test's master checks the boot-up, reads every
// default, writes and reads back, and sees the EDS's PDOs on the bus.
#include <gtest/gtest.h>

#include "tests/system/node/eds_defaults.hpp"
#include "tests/system/node/node_system_support.hpp"

namespace canfleet::system_test {
namespace {

using canopen::SdoAbort;

constexpr std::uint8_t kNodeId = 9;
const std::string kEds = std::string(CANFLEET_NODE_TEST_DATA) + "/brightwater-tx4.eds";

class CanfleetNodeGeneric : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_FALSE(broker_.endpoint().empty());
    ASSERT_TRUE(broker_.endpoint().starts_with("unix://")) << broker_.endpoint();
    ASSERT_TRUE(master_.WaitConnected()) << broker_.Log();
    node_ = std::make_unique<NodeProcess>(
        dir_, "tx4",
        std::vector<std::string>{"--eds", kEds, "--node-id", "9", "--bus", "can0@" + broker_.endpoint()});
    // CiA 301 §7.2.8.3.3 boot-up: 700h + node-ID, one byte 00h.
    ASSERT_TRUE(master_.WaitForFrame("709#00")) << node_->Output();
  }

  std::string ReadString(std::uint16_t index, std::uint8_t sub) {
    const auto r = master_.Read(kNodeId, index, sub);
    if (r.abort != SdoAbort::kNone) return "abort " + AbortText(r.abort);
    return std::string(r.data.begin(), r.data.end());
  }

  TempDir dir_;
  BrokerProcess broker_{dir_, "unix://" + dir_.File("bus.sock")};
  BusMaster master_{broker_.endpoint()};
  std::unique_ptr<NodeProcess> node_;
};

TEST_F(CanfleetNodeGeneric, ServesEveryDefaultOfTheThirdPartyEds) {
  const EdsContents eds = ReadEdsDefaults(kEds, kNodeId);
  ASSERT_TRUE(eds.problems.empty()) << ::testing::PrintToString(eds.problems);
  const EdsComparison result = CompareWithEds(master_, kNodeId, eds);
  std::string report;
  for (const auto& line : result.mismatches)
    report += "  " + line + "\n";
  EXPECT_TRUE(result.mismatches.empty()) << report;
  EXPECT_EQ(result.compared + result.refused, eds.entries.size());
  EXPECT_GE(result.compared, 50u);

  // The same values, spelled out as the vendor meant them.
  EXPECT_EQ(master_.ReadUnsigned(kNodeId, 0x1000, 0), 0x00020194u);       // CiA 404, AI
  EXPECT_EQ(master_.ReadUnsigned(kNodeId, 0x1018, 1), 0x0000B1E5u);       // vendor-ID
  EXPECT_EQ(master_.ReadUnsigned(kNodeId, 0x1014, 0), 0x80u + kNodeId);   // $NODEID+0x80
  EXPECT_EQ(master_.ReadUnsigned(kNodeId, 0x1400, 1), 0x200u + kNodeId);  // $NODEID+0x200
  EXPECT_EQ(master_.ReadUnsigned(kNodeId, 0x1800, 1), 0x180u + kNodeId);  // $NODEID+0x180
  EXPECT_EQ(ReadString(0x1008, 0), "BW-TX4 Temperature Transmitter");     // segmented upload
  EXPECT_EQ(ReadString(0x2100, 1), "UNTAGGED");
  EXPECT_EQ(master_.ReadUnsigned(kNodeId, 0x6126, 0), static_cast<std::uint32_t>(-100000));  // INTEGER32
  EXPECT_EQ(master_.ReadUnsigned(kNodeId, 0x61A0, 0), 0xFDu);                                // INTEGER8 -3
  EXPECT_EQ(master_.ReadUnsigned(kNodeId, 0x7130, 2), 0xFFD8u);                              // INTEGER16 -40
}

TEST_F(CanfleetNodeGeneric, WritesAreKeptAndTheEdsLimitsAndAccessApply) {
  // Within 2000h's LowLimit/HighLimit (0..1500): kept.
  EXPECT_EQ(master_.Write(kNodeId, 0x2000, 2, 1234, 2), SdoAbort::kNone);
  EXPECT_EQ(master_.ReadUnsigned(kNodeId, 0x2000, 2), 1234u);
  EXPECT_EQ(master_.ReadUnsigned(kNodeId, 0x2000, 3), 800u);  // its neighbour untouched
  // CiA 301 §7.2.4.3.17: beyond the limit 06090031h, a const object 06010002h; the value stays.
  EXPECT_EQ(master_.Write(kNodeId, 0x2000, 2, 1501, 2), SdoAbort::kValueTooHigh);
  EXPECT_EQ(master_.ReadUnsigned(kNodeId, 0x2000, 2), 1234u);
  EXPECT_EQ(master_.Write(kNodeId, 0x1018, 1, 0, 4), SdoAbort::kReadOnly);
  EXPECT_EQ(master_.Download(kNodeId, 0x1008, 0, {'X'}), SdoAbort::kReadOnly);
  EXPECT_EQ(master_.Write(kNodeId, 0x6126, 0, static_cast<std::uint32_t>(-2000000), 4),
            SdoAbort::kValueTooLow);

  // A string longer than the default, by segmented download, read back by segmented upload.
  const std::string tag = "TANK 2 OUTLET, NORTH";
  EXPECT_EQ(master_.Download(kNodeId, 0x2100, 1, canopen::Bytes(tag.begin(), tag.end())), SdoAbort::kNone);
  EXPECT_EQ(ReadString(0x2100, 1), tag);
  // A BOOLEAN.
  EXPECT_EQ(master_.Write(kNodeId, 0x2100, 3, 1, 1), SdoAbort::kNone);
  EXPECT_EQ(master_.ReadUnsigned(kNodeId, 0x2100, 3), 1u);

  // CiA 301 §7.2.8.3.2.1: a heartbeat once 1017h is set, in pre-operational (7Fh).
  const std::size_t before = master_.Frames().size();
  EXPECT_EQ(master_.Write(kNodeId, 0x1017, 0, 100, 2), SdoAbort::kNone);
  EXPECT_TRUE(master_.WaitForFrame("709#7F", before));
  EXPECT_EQ(master_.ReadUnsigned(kNodeId, 0x1017, 0), 100u);
}

TEST_F(CanfleetNodeGeneric, TheEdsDefaultPdosRunInOperational) {
  ASSERT_TRUE(master_.Nmt(BusMaster::kNmtStart, kNodeId));
  // TPDO1: $NODEID+0x180, type FEh, event timer 200 ms, 7130h.1-4 as INTEGER16:
  // 215 = 00D7h, -40 = FFD8h, 0x0100, 0.
  ASSERT_TRUE(master_.WaitForFrame("189#D700D8FF00010000")) << node_->Output();

  // RPDO1: $NODEID+0x200, maps 2000h.1 (16 bits). 700 = 02BCh.
  ASSERT_TRUE(master_.port().Send(CanFrame::Data(0x209, {0xBC, 0x02})));
  EXPECT_TRUE(master_.RunUntil([&] { return master_.ReadUnsigned(kNodeId, 0x2000, 1) == 700u; }));
}

}  // namespace
}  // namespace canfleet::system_test
