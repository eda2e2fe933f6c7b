// What the orchestrator writes into a node after its boot-up (orchestrator/topology/configuration_plan).
#include "orchestrator/topology/configuration_plan.hpp"

#include <google/protobuf/text_format.h>
#include <gtest/gtest.h>

#include <fstream>

namespace canfleet::topology {
namespace {

// A node's topology entry with its ports' buses and node-IDs, as the fleet knows it.
struct FleetNode {
  Node spec;
  std::vector<std::string> buses;
  std::vector<std::uint8_t> node_ids;
};

std::optional<std::uint8_t> Lookup(const std::string& name, const std::string& bus);

FleetNode NodeFrom(const std::string& text) {
  FleetNode node;
  EXPECT_TRUE(google::protobuf::TextFormat::ParseFromString(text, &node.spec));
  node.buses.assign(node.spec.bus().begin(), node.spec.bus().end());
  for (const auto id : node.spec.node_id())
    node.node_ids.push_back(static_cast<std::uint8_t>(id));
  return node;
}

std::vector<PlannedWrite> Plan(const FleetNode& node, std::size_t port) {
  return PlanConfiguration(node.spec, node.buses, node.node_ids, port, Lookup);
}

std::optional<std::uint8_t> Lookup(const std::string& name, const std::string& bus) {
  if (name == "quad-5" && bus == "can0") return 5;
  return std::nullopt;
}

TEST(ConfigurationPlan, HeartbeatProducerThenConsumersThenSdoWritesInOrder) {
  const auto node = NodeFrom(R"(name: "quad-6" node_id: 6 bus: "can0"
    heartbeat { producer_ms: 500 consumer { node: "quad-5" timeout_ms: 1500 } consumer { node_id: 9 timeout_ms: 100 } }
    sdo { index: 0x1400 subindex: 5 type: "u16" value: "250" })");
  const auto plan = Plan(node, 0);
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
  // Each write names the field it comes from (the loader's warnings point there).
  EXPECT_EQ(plan[0].source.field, PlanSource::Field::kProducer);
  EXPECT_EQ(plan[2].source.field, PlanSource::Field::kConsumer);
  EXPECT_EQ(plan[2].source.index, 1);
  EXPECT_EQ(plan[3].source.field, PlanSource::Field::kSdo);
  EXPECT_EQ(plan[3].source.index, 0);
}

TEST(ConfigurationPlan, NothingConfiguredMeansNoWrites) {
  EXPECT_TRUE(Plan(NodeFrom(R"(name: "a" node_id: 1 bus: "can0")"), 0).empty());
}

TEST(ConfigurationPlan, SdoWritesGoToTheirPort) {
  const auto node = NodeFrom(R"(name: "logger" node_id: 1 bus: "can0" bus: "can1"
    sdo { index: 0x1017 type: "u16" value: "100" port: 1 })");
  EXPECT_TRUE(Plan(node, 0).empty());
  EXPECT_EQ(Plan(node, 1).size(), 1u);
}

TEST(ConfigurationPlan, ConsumerOfANodeOnAnotherBusIsRefused) {
  const auto node = NodeFrom(R"(name: "x" node_id: 2 bus: "can1"
    heartbeat { consumer { node: "quad-5" timeout_ms: 100 } })");
  EXPECT_THROW(Plan(node, 0), std::invalid_argument);
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
  const auto plan = Plan(node, 0);
  ASSERT_EQ(plan.size(), 1u);
  EXPECT_EQ(plan[0].index, 0x1017);
  EXPECT_EQ(plan[0].data, (std::vector<std::uint8_t>{0xFA, 0x00}));
}

}  // namespace
}  // namespace canfleet::topology
