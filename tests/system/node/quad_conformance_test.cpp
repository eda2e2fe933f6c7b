// SDO conformance of a running Quad process against its EDS (issue 5: "an SDO conformance test
// that reads every object of the Quad's EDS from a running node and compares it with the EDS
// default").
//
// canfleet-broker + canfleet-node --device quad-controller --node-id 5; the test's master reads
// every sub-object of node/devices/quad_controller/quad-controller.eds after the boot-up and
// before any configuration, and compares it with the file's DefaultValue as an independent reader
// sees it (eds_defaults.hpp; $NODEID applied, size and bytes compared). The manual gives the
// measured objects (7100h, 7130h, 30C0h, 6000h, 300Ch) no default beyond 0, so the node runs with
// its simulated inputs at 0 V / 0 % (--io): then every object has the value the EDS says.
#include <gtest/gtest.h>

#include "tests/system/node/eds_defaults.hpp"
#include "tests/system/node/node_system_support.hpp"

namespace canfleet::system_test {
namespace {

using canopen::SdoAbort;

constexpr std::uint8_t kNodeId = 5;

class CanfleetNodeQuadConformance : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_FALSE(broker_.endpoint().empty());
    ASSERT_TRUE(master_.WaitConnected()) << broker_.Log();
    std::vector<std::string> args = {"--device",  "quad-controller",
                                     "--node-id", std::to_string(kNodeId),
                                     "--bus",     "can0@" + broker_.endpoint()};
    for (const char* input : {"IN1.voltage_mV=0", "IN2.voltage_mV=0", "IN3.voltage_mV=0", "IN4.voltage_mV=0",
                              "IN5.duty_pct=0", "IN6.duty_pct=0"}) {
      args.push_back("--io");
      args.push_back(input);
    }
    node_ = std::make_unique<NodeProcess>(dir_, "quad5", args);
    ASSERT_TRUE(master_.WaitForFrame("705#00")) << node_->Output();
  }

  TempDir dir_;
  BrokerProcess broker_{dir_, "tcp://127.0.0.1:0"};
  BusMaster master_{broker_.endpoint()};
  std::unique_ptr<NodeProcess> node_;
};

TEST_F(CanfleetNodeQuadConformance, EveryObjectOfTheEdsReadsItsDefault) {
  const EdsContents eds = ReadEdsDefaults(CANFLEET_QUAD_EDS, kNodeId);
  ASSERT_TRUE(eds.problems.empty()) << ::testing::PrintToString(eds.problems);
  // Not a vacuous pass: the manual's objects (§3.1-§3.5) are 464 sub-objects.
  ASSERT_EQ(eds.entries.size(), 464u);

  const EdsComparison result = CompareWithEds(master_, kNodeId, eds);
  std::string report;
  for (const auto& line : result.mismatches)
    report += "  " + line + "\n";
  EXPECT_TRUE(result.mismatches.empty()) << result.mismatches.size() << " of " << eds.entries.size()
                                         << " sub-objects differ from quad-controller.eds:\n"
                                         << report;
  // All but the 6 write-only autozero commands (6125h.1-6) and the 16 empty 1003h entries.
  EXPECT_EQ(result.compared, 442u);
  EXPECT_EQ(result.refused, 22u);
  EXPECT_TRUE(node_->process().Running()) << node_->Output();
}

// CiA 301 §7.2.4.3.17 abort codes for what a master may get wrong.
TEST_F(CanfleetNodeQuadConformance, WriteOnlyAndMissingObjectsAbortWithTheirCodes) {
  struct Case {
    const char* what;
    std::uint16_t index;
    std::uint8_t sub;
    SdoAbort expected;
  };
  const std::vector<Case> reads = {
      {"6125h AI Autozero is write-only (manual §3.3.20)", 0x6125, 1, SdoAbort::kWriteOnly},
      {"1003h.1 with no error recorded", 0x1003, 1, SdoAbort::kNoData},
      {"no object 2222h", 0x2222, 0, SdoAbort::kNoObject},
      {"no object 1005h (no SYNC objects, manual §3.1)", 0x1005, 0, SdoAbort::kNoObject},
      {"2000h has sub-indexes 0-1 only", 0x2000, 2, SdoAbort::kNoSubIndex},
      {"7100h has sub-indexes 0-6 only", 0x7100, 7, SdoAbort::kNoSubIndex},
  };
  for (const Case& c : reads) {
    const auto got = master_.Read(kNodeId, c.index, c.sub);
    EXPECT_EQ(got.abort, c.expected) << c.what << ": got " << AbortText(got.abort) << " "
                                     << HexBytes(got.data);
  }
  const std::vector<Case> writes = {
      {"1000h Device Type is read-only", 0x1000, 0, SdoAbort::kReadOnly},
      {"no object 2222h", 0x2222, 0, SdoAbort::kNoObject},
      {"7100h.8 does not exist", 0x7100, 8, SdoAbort::kNoSubIndex},
  };
  for (const Case& c : writes) {
    const auto got = master_.Write(kNodeId, c.index, c.sub, 0, 4);
    EXPECT_EQ(got, c.expected) << c.what << ": got " << AbortText(got);
  }
  // A wrong length for a 16-bit object (CiA 301: 06070010h/06070012h/06070013h).
  EXPECT_EQ(master_.Write(kNodeId, 0x1017, 0, 100, 4), SdoAbort::kLengthTooHigh);
  EXPECT_EQ(master_.Write(kNodeId, 0x1017, 0, 100, 1), SdoAbort::kLengthTooLow);
}

}  // namespace
}  // namespace canfleet::system_test
