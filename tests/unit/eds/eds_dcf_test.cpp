// DCF reading, CiA 306 v1.3 §5: [DeviceComissioning] and ParameterValue (the configured value,
// which becomes the current value while DefaultValue stays the default).
#include <gtest/gtest.h>

#include "node/canopen/eds/eds_reader.hpp"
#include "tests/unit/eds/eds_test_util.hpp"

namespace canfleet::canopen {
namespace {

using test::ExpectEdsError;

class DcfFixtureTest : public ::testing::Test {
 protected:
  void SetUp() override { dcf = ReadEds(test::DataPath("ds401_io_node5.dcf")); }
  EdsFile dcf;
};

TEST_F(DcfFixtureTest, DeviceCommissioning) {
  EXPECT_EQ(dcf.dcf_node_id, 5);
  EXPECT_EQ(dcf.dcf_baudrate_kbit, 250u);
  EXPECT_EQ(dcf.commissioning.node_name, "io-left");
  EXPECT_EQ(dcf.commissioning.net_number, 1u);
  EXPECT_EQ(dcf.commissioning.network_name, "bench");
  EXPECT_EQ(dcf.commissioning.canopen_manager, false);
  EXPECT_EQ(dcf.commissioning.lss_serial_number, 0x1234u);
  EXPECT_EQ(dcf.file_info.last_eds, "ds401_io.eds");
}

TEST_F(DcfFixtureTest, ParameterValueIsTheCurrentValue) {
  EXPECT_EQ(dcf.od.Find(0x1017, 0)->value, EncodeLe<std::uint16_t>(500));
  EXPECT_EQ(dcf.od.Find(0x1017, 0)->default_value, EncodeLe<std::uint16_t>(0));
  EXPECT_EQ(dcf.od.Find(0x1008, 0)->value, ToBytes("IO-401 left"));
  EXPECT_EQ(dcf.od.Find(0x1008, 0)->default_value, ToBytes("IO-401"));
  EXPECT_EQ(dcf.od.Find(0x1800, 2)->value, Bytes{1});
}

// "$NODEID" in ParameterValue is resolved with the DCF's NodeID; without a ParameterValue the
// current value is the default with the NodeID applied.
TEST_F(DcfFixtureTest, NodeIdIsAppliedToValues) {
  const SubObject* cob_id = dcf.od.Find(0x1800, 1);
  EXPECT_EQ(cob_id->value, EncodeLe<std::uint32_t>(0x40000185));
  EXPECT_EQ(cob_id->default_value, EncodeLe<std::uint32_t>(0x180));
  EXPECT_TRUE(cob_id->default_adds_node_id);
  EXPECT_EQ(dcf.od.Find(0x1001, 0)->value, Bytes{0});
}

TEST_F(DcfFixtureTest, CompactValueSection) {
  EXPECT_EQ(dcf.od.Find(0x6200, 1)->value, Bytes{0});
  EXPECT_EQ(dcf.od.Find(0x6200, 2)->value, Bytes{0xA5});
  EXPECT_EQ(dcf.od.Find(0x6200, 2)->default_value, Bytes{0});
}

TEST(DcfTest, EdsDefaultsGetTheNodeIdWhenTheFileHasOne) {
  auto dcf = ParseEds(
      "[2000]\nParameterName=x\nDataType=7\nAccessType=rw\nDefaultValue=$NODEID+0x600\n"
      "[DeviceCommissioning]\nNodeID=0x7F\n",  // the spelling tools fix is read too
      "t.dcf");
  EXPECT_EQ(dcf.od.Find(0x2000, 0)->value, EncodeLe<std::uint32_t>(0x67F));
}

TEST(DcfTest, CommissioningErrors) {
  ExpectEdsError("[2000]\nParameterName=x\nDataType=7\nAccessType=rw\nParameterValue=$NODEID+1\n",
                 {5, "2000", "ParameterValue", "$NODEID needs [DeviceComissioning] NodeID"});
  ExpectEdsError("[DeviceComissioning]\nNodeID=0\n",
                 {2, "DeviceComissioning", "NodeID", "out of range (1..127)"});
  ExpectEdsError("[DeviceComissioning]\nNodeID=128\n",
                 {2, "DeviceComissioning", "NodeID", "\"128\" is out of range (1..127)"});
  ExpectEdsError("[DeviceComissioning]\nBaudrate=fast\n",
                 {2, "DeviceComissioning", "Baudrate", "\"fast\" is not a number"});
  ExpectEdsError("[DeviceComissioning]\n[DeviceCommissioning]\n",
                 {2, "DeviceCommissioning", "", "duplicate section (first on line 1)"});
  ExpectEdsError("[2000]\nParameterName=x\nDataType=5\nAccessType=rw\nParameterValue=256\n",
                 {5, "2000", "ParameterValue", "\"256\" is out of range for UNSIGNED8"});
}

}  // namespace
}  // namespace canfleet::canopen
