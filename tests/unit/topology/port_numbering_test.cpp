// CAN ports in topology files as the manuals print them (issue 29, "one port numbering"): the
// data logger's second port is CAN2 in its manual (UMAX181001 §1.1), `can: 2` in a topology file,
// `--port 2` on the command line; the loader hands the orchestrator the wire's 0-based port.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "orchestrator/topology/topology_loader.hpp"

namespace canfleet::topology {
namespace {

using ::testing::HasSubstr;
using ::testing::IsEmpty;
using ::testing::SizeIs;

constexpr const char* kFile = "ports.textproto";

// A data logger on two buses, and what follows `extra` (a scenario line).
std::string Logger(const std::string& sdo, const std::string& extra = "") {
  return R"(name: "ports"
bus { name: "can0" }
bus { name: "can1" }
node { name: "logger" device: "datalogger-tc-analog" node_id: 10 node_id: 11 bus: "can0" bus: "can1"
  sdo { )" +
         sdo + R"( index: 0x1017 type: "u16" value: "500" } }
)" + extra;
}

std::string RefusalOf(const std::string& text) {
  try {
    (void)ParseTopology(text, kFile);
  } catch (const TopologyError& e) {
    return e.what();
  }
  ADD_FAILURE() << "loaded without error:\n" << text;
  return "";
}

TEST(PortNumbering, CanCountsFromOneAsTheManualPrintsIt) {
  const LoadedTopology t = ParseTopology(Logger("can: 2"), kFile);
  EXPECT_EQ(t.spec.node(0).sdo(0).port(), 1u);  // the wire's 0-based port of CAN2
  EXPECT_THAT(t.warnings, IsEmpty());
  EXPECT_EQ(ParseTopology(Logger("can: 1"), kFile).spec.node(0).sdo(0).port(), 0u);
  EXPECT_EQ(ParseTopology(Logger(""), kFile).spec.node(0).sdo(0).port(), 0u);  // CAN1 by default
}

TEST(PortNumbering, TheOldZeroBasedPortLoadsWithADeprecationNote) {
  const LoadedTopology t = ParseTopology(Logger("port: 1"), kFile);
  EXPECT_EQ(t.spec.node(0).sdo(0).port(), 1u);
  ASSERT_THAT(t.warnings, SizeIs(1));
  EXPECT_EQ(t.warnings[0].Message(),
            "ports.textproto:5:9: warning: node[0].sdo[0].port: deprecated: port: 1 counts from 0; write "
            "can: 2 (CAN2, as the manuals print the ports)");
}

TEST(PortNumbering, ExpectationsAndScenarioStepsUseCanToo) {
  const std::string text =
      Logger("can: 2",
             R"(scenario { sdo { node: "logger" can: 2 index: 0x1017 type: "u16" value: "600" } }
scenario { expect { within_ms: 100 emcy { node: "logger" can: 2 code: 0 } } }
scenario { expect { within_ms: 100 nmt { node: "logger" can: 2 state: "operational" } } }
scenario { expect { sdo { node: "logger" can: 2 index: 0x1017 type: "u16" value: "600" } } }
scenario { expect { within_ms: 100 no_emcy { node: "logger" can: 1 } } }
scenario { expect { controller { node: "logger" can: 2 state: "error-active" } } }
)");
  const LoadedTopology t = ParseTopology(text, kFile);
  EXPECT_THAT(t.warnings, IsEmpty());
  EXPECT_EQ(t.spec.scenario(0).sdo().port(), 1u);
  EXPECT_EQ(t.spec.scenario(1).expect().emcy().port(), 1u);
  EXPECT_EQ(t.spec.scenario(2).expect().nmt().port(), 1u);
  EXPECT_EQ(t.spec.scenario(3).expect().sdo().port(), 1u);
  EXPECT_EQ(t.spec.scenario(4).expect().no_emcy().port(), 0u);
  EXPECT_EQ(t.spec.scenario(5).expect().controller().port(), 1u);
}

TEST(PortNumbering, APortTheNodeLacksIsNamedAsTheManualNamesIt) {
  const std::string quad = R"(name: "q" bus { name: "can0" }
node { name: "quad-5" device: "quad-controller" node_id: 5 bus: "can0" }
scenario { expect { within_ms: 100 emcy { node: "quad-5" can: 2 code: 0 } } }
)";
  EXPECT_THAT(
      RefusalOf(quad),
      HasSubstr(":3:58: scenario[0].expect.emcy.can: CAN2 does not exist: quad-5 has 1 CAN port (CAN1)"));
}

TEST(PortNumbering, CanAndPortTogetherOrACanBeyondTwoAreRefused) {
  EXPECT_THAT(
      RefusalOf(Logger("can: 2 port: 1")),
      HasSubstr("node[0].sdo[0].port: give the port once: can: 2 (as the manual prints it) replaces the "
                "deprecated port"));
  EXPECT_THAT(
      RefusalOf(Logger("can: 3")),
      HasSubstr("node[0].sdo[0].can: CAN3: ports are numbered as the manuals print them, can: 1 (CAN1) or "
                "can: 2 (CAN2)"));
}

}  // namespace
}  // namespace canfleet::topology
