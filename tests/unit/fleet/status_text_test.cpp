// `canfleet status`: a port whose controller runs at another bit rate than its bus shows that rate
// next to its controller state (PortStatus.bitrate; orchestrator/broker/README.md "Bit rate").
#include <gtest/gtest.h>

#include "tools/canfleet/text_format.hpp"

namespace canfleet::cli {
namespace {

control::Status OneBus() {
  control::Status status;
  status.set_topology("t");
  auto* bus = status.add_buses();
  bus->set_name("can0");
  bus->set_bitrate(500'000);
  return status;
}

control::NodeStatus& AddNode(control::Status& status, const std::string& name, int ports) {
  auto* node = status.add_nodes();
  node->set_name(name);
  node->set_device("valve-12in12out");
  for (int p = 0; p < ports; ++p) {
    node->add_node_ids(static_cast<std::uint32_t>(5 + p));
    node->add_buses("can0");
    auto* port = node->add_ports();
    port->set_bus("can0");
    port->set_node_id(static_cast<std::uint32_t>(5 + p));
    port->set_controller("error-active");
  }
  node->set_controller("error-active");
  return *node;
}

TEST(StatusText, APortAtAnotherRateShowsItsRateAfterItsState) {
  control::Status status = OneBus();
  control::NodeStatus& b = AddNode(status, "b", 1);
  b.mutable_ports(0)->set_controller("error-passive");
  b.mutable_ports(0)->set_bitrate(250'000);
  b.set_controller("error-passive");
  AddNode(status, "a", 1);
  const std::string text = FormatStatus(status);
  EXPECT_NE(text.find("error-passive @250k"), std::string::npos) << text;
  EXPECT_EQ(text.find("error-active @"), std::string::npos) << text;  // a runs at the bus's rate
}

TEST(StatusText, EachPortOfATwoPortNodeShowsItsOwnRate) {
  control::Status status = OneBus();
  control::NodeStatus& d = AddNode(status, "d", 2);
  d.mutable_ports(1)->set_bitrate(125'000);
  const std::string text = FormatStatus(status);
  EXPECT_NE(text.find("error-active @125k"), std::string::npos) << text;
  EXPECT_EQ(text.find("@500k"), std::string::npos) << text;
}

}  // namespace
}  // namespace canfleet::cli
