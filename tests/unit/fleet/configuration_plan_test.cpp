// What the orchestrator writes into a node after its boot-up (orchestrator/fleet/configuration_plan).
#include "orchestrator/fleet/configuration_plan.hpp"

#include <google/protobuf/text_format.h>
#include <gtest/gtest.h>

#include <fstream>

namespace canfleet::fleet {
namespace {

FleetNode NodeFrom(const std::string& text) {
  FleetNode node;
  EXPECT_TRUE(google::protobuf::TextFormat::ParseFromString(text, &node.spec));
  node.buses.assign(node.spec.bus().begin(), node.spec.bus().end());
  for (const auto id : node.spec.node_id())
    node.node_ids.push_back(static_cast<std::uint8_t>(id));
  return node;
}

std::optional<std::uint8_t> Lookup(const std::string& name, const std::string& bus) {
  if (name == "quad-5" && bus == "can0") return 5;
  return std::nullopt;
}

TEST(ConfigurationPlan, HeartbeatProducerThenConsumersThenSdoWritesInOrder) {
  const auto node = NodeFrom(R"(name: "quad-6" node_id: 6 bus: "can0"
    heartbeat { producer_ms: 500 consumer { node: "quad-5" timeout_ms: 1500 } consumer { node_id: 9 timeout_ms: 100 } }
    sdo { index: 0x1400 subindex: 5 type: "u16" value: "250" })");
  const auto plan = PlanConfiguration(node, 0, Lookup);
  ASSERT_EQ(plan.size(), 4u);
  EXPECT_EQ(plan[0].index, 0x1017);
  EXPECT_EQ(plan[0].data, (std::vector<std::uint8_t>{0xF4, 0x01}));
  // CiA 301 §7.5.2.28: node-ID in bits 16..23, time in ms in bits 0..15.
  EXPECT_EQ(plan[1].index, 0x1016);
  EXPECT_EQ(plan[1].subindex, 1);
  EXPECT_EQ(plan[1].data, (std::vector<std::uint8_t>{0xDC, 0x05, 0x05, 0x00}));
  EXPECT_EQ(plan[2].subindex, 2);
  EXPECT_EQ(plan[2].data, (std::vector<std::uint8_t>{0x64, 0x00, 0x09, 0x00}));
  EXPECT_EQ(plan[3].index, 0x1400);
  EXPECT_EQ(plan[3].subindex, 5);
  EXPECT_EQ(plan[3].data, (std::vector<std::uint8_t>{0xFA, 0x00}));
}

TEST(ConfigurationPlan, NothingConfiguredMeansNoWrites) {
  EXPECT_TRUE(PlanConfiguration(NodeFrom(R"(name: "a" node_id: 1 bus: "can0")"), 0, Lookup).empty());
}

TEST(ConfigurationPlan, SdoWritesGoToTheirPort) {
  const auto node = NodeFrom(R"(name: "logger" node_id: 1 bus: "can0" bus: "can1"
    sdo { index: 0x1017 type: "u16" value: "100" port: 1 })");
  EXPECT_TRUE(PlanConfiguration(node, 0, Lookup).empty());
  EXPECT_EQ(PlanConfiguration(node, 1, Lookup).size(), 1u);
}

TEST(ConfigurationPlan, ConsumerOfANodeOnAnotherBusIsRefused) {
  const auto node = NodeFrom(R"(name: "x" node_id: 2 bus: "can1"
    heartbeat { consumer { node: "quad-5" timeout_ms: 100 } })");
  EXPECT_THROW(PlanConfiguration(node, 0, Lookup), std::invalid_argument);
}

TEST(ConfigurationPlan, DcfValuesThatDifferFromTheDefaultsAreWritten) {
  const std::string dcf = ::testing::TempDir() + "/plan_test.dcf";
  std::ofstream(dcf) << R"([DeviceInfo]
VendorName=test
[MandatoryObjects]
SupportedObjects=2
1=0x1000
2=0x1017
[1000]
ParameterName=Device type
ObjectType=0x7
DataType=0x0007
AccessType=ro
DefaultValue=0
ParameterValue=0
PDOMapping=0
[1017]
ParameterName=Producer heartbeat time
ObjectType=0x7
DataType=0x0006
AccessType=rw
DefaultValue=0
ParameterValue=250
PDOMapping=0
)";
  auto node = NodeFrom(R"(name: "a" node_id: 3 bus: "can0")");
  node.spec.set_dcf(dcf);
  const auto plan = PlanConfiguration(node, 0, Lookup);
  ASSERT_EQ(plan.size(), 1u);
  EXPECT_EQ(plan[0].index, 0x1017);
  EXPECT_EQ(plan[0].data, (std::vector<std::uint8_t>{0xFA, 0x00}));
}

}  // namespace
}  // namespace canfleet::fleet
