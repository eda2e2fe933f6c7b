// Topology files (topologies/README.md): syntax errors with file:line:col, semantic errors naming
// the field and its line, the defaults the fleet manager relies on, path resolution, and every
// topology shipped in topologies/ loading cleanly.

#include "orchestrator/topology/topology_loader.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace canfleet::topology {
namespace {

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::StartsWith;

const fs::path kSourceDir = CANFLEET_SOURCE_DIR;
const fs::path kTopologies = kSourceDir / "topologies";
const fs::path kDioEds = kTopologies / "eds" / "canfleet-dio16.eds";

// A file name in a folder that exists, so relative paths resolve somewhere real.
const fs::path kFile = kTopologies / "test.textproto";

// The error ParseTopology gives for `text`; fails the test when it loads.
TopologyError Refusal(const std::string& text, const fs::path& file = kFile) {
  try {
    (void)ParseTopology(text, file);
  } catch (const TopologyError& e) {
    return e;
  }
  ADD_FAILURE() << "loaded without error:\n" << text;
  return TopologyError("", 0, 0, "", "");
}

LoadedTopology Load(const std::string& text, const fs::path& file = kFile) {
  try {
    return ParseTopology(text, file);
  } catch (const TopologyError& e) {
    ADD_FAILURE() << e.what();
    throw;
  }
}

// Two Quads on can0, nodes 5 and 6: the base most tests add to.
const std::string kTwoQuads = R"(name: "t"
bus { name: "can0" bitrate: 250000 }
node { name: "quad-5" device: "quad-controller" node_id: 5 bus: "can0" }
node { name: "quad-6" device: "quad-controller" node_id: 6 bus: "can0" }
)";

// ---- syntax -----------------------------------------------------------------------------------

TEST(TopologySyntaxTest, AMissingColonIsReportedWithFileLineAndColumn) {
  const TopologyError e = Refusal("name: \"t\"\nbus { name: \"can0\" bitrate 250000 }\n", "demo.textproto");
  EXPECT_THAT(e.what(), StartsWith("demo.textproto:2:28: syntax error: "));
  EXPECT_THAT(e.what(), HasSubstr("\":\""));
  EXPECT_EQ(e.line(), 2);
  EXPECT_EQ(e.column(), 28);
  EXPECT_EQ(e.field(), "");
}

TEST(TopologySyntaxTest, AnUnknownFieldIsNamed) {
  const TopologyError e = Refusal("name: \"t\"\n\nnode {\n  nodeid: 5\n}\n", "x.textproto");
  EXPECT_THAT(e.what(), AllOf(StartsWith("x.textproto:4:9: syntax error: "), HasSubstr("nodeid")));
}

TEST(TopologySyntaxTest, AnUnknownEnumValueIsASyntaxError) {
  const TopologyError e = Refusal(kTwoQuads + "scenario { inject { kind: BUS_OOF node: \"quad-5\" } }\n");
  EXPECT_THAT(e.what(),
              AllOf(HasSubstr("test.textproto:5:"), HasSubstr("syntax error"), HasSubstr("BUS_OOF")));
}

TEST(TopologySyntaxTest, AnUnterminatedMessageIsASyntaxError) {
  const TopologyError e = Refusal("name: \"t\"\nbus { name: \"can0\"\n");
  EXPECT_THAT(e.what(), AllOf(StartsWith(kFile.string() + ":"), HasSubstr("syntax error")));
  EXPECT_GT(e.line(), 0);
}

// ---- node-IDs ---------------------------------------------------------------------------------

TEST(TopologyNodeIdTest, ADuplicateNodeIdNamesTheLineAndBothNodes) {
  const std::string text = R"(name: "t"
bus { name: "can0" }
node {
  name: "quad-5"
  device: "quad-controller"
  node_id: 5
  bus: "can0"
}
node { name: "quad-6" device: "quad-controller" node_id: 5 bus: "can0" }
)";
  const TopologyError e = Refusal(text, "demo.textproto");
  EXPECT_STREQ(e.what(),
               "demo.textproto:9:49: node[1].node_id: quad-6 has node-ID 5 on bus can0, already used by node "
               "quad-5 (line 6)");
  EXPECT_EQ(e.field(), "node[1].node_id");
  EXPECT_EQ(e.line(), 9);
}

TEST(TopologyNodeIdTest, TheSameNodeIdOnTwoBusesIsFine) {
  const LoadedTopology t = Load(R"(name: "t"
bus { name: "can0" } bus { name: "can1" }
node { name: "a" device: "quad-controller" node_id: 5 bus: "can0" }
node { name: "b" device: "quad-controller" node_id: 5 bus: "can1" }
)");
  EXPECT_EQ(t.spec.node_size(), 2);
}

TEST(TopologyNodeIdTest, NodeIdsOutOfRangeAreRefused) {
  for (const std::string id : {"0", "128", "254", "1000"}) {
    const TopologyError e = Refusal(
        "name: \"t\" bus { name: \"can0\" }\nnode { name: \"q\" device: \"quad-controller\" "
        "bus: \"can0\" node_id: " +
        id + " }\n");
    EXPECT_THAT(e.what(), AllOf(HasSubstr(":2:"), HasSubstr("node[0].node_id: " + id + " is not a node-ID")));
  }
}

TEST(TopologyNodeIdTest, UnconfiguredLssSlavesNeedDistinctSerials) {
  const std::string base = R"(name: "t" bus { name: "can0" }
node { name: "a" device: "quad-controller" node_id: 255 bus: "can0" serial: 1 }
)";
  EXPECT_NO_THROW(ParseTopology(
      base + "node { name: \"b\" device: \"quad-controller\" node_id: 255 bus: \"can0\" serial: 2 }", kFile));
  const TopologyError e =
      Refusal(base + "node { name: \"b\" device: \"quad-controller\" node_id: 255 bus: \"can0\" serial: 1 }");
  EXPECT_THAT(e.what(), AllOf(HasSubstr("node[1].serial"), HasSubstr("b and a are both unconfigured")));
}

TEST(TopologyNodeIdTest, AMissingNodeIdIsRefused) {
  const TopologyError e = Refusal(
      "name: \"t\" bus { name: \"can0\" }\n\nnode { name: \"q\" device: \"quad-controller\" bus: \"can0\" }");
  EXPECT_THAT(e.what(), HasSubstr(":3:1: node[0]: node q needs node_id"));
}

// ---- buses ------------------------------------------------------------------------------------

TEST(TopologyBusTest, AnUnknownBusIsNamedWithTheKnownOnes) {
  const TopologyError e = Refusal(R"(name: "t"
bus { name: "can0" }
bus { name: "can1" }
node { name: "q" device: "quad-controller" node_id: 5 bus: "can9" }
)");
  EXPECT_THAT(
      e.what(),
      HasSubstr("test.textproto:4:55: node[0].bus: unknown bus \"can9\" (the topology's buses: can0, can1)"));
}

TEST(TopologyBusTest, BusesAreRequiredUniqueAndInRange) {
  EXPECT_THAT(Refusal("name: \"t\"\n").what(), HasSubstr("bus: at least one bus is required"));
  EXPECT_THAT(Refusal("name: \"t\" bus { name: \"can0\" }\nbus { name: \"can0\" }").what(),
              HasSubstr(":2:7: bus[1].name: bus can0 is already defined (bus[0], line 1)"));
  EXPECT_THAT(Refusal("name: \"t\" bus { bitrate: 250000 }").what(), HasSubstr("bus[0].name: required"));
  EXPECT_THAT(Refusal("name: \"t\" bus { name: \"can 0\" }").what(), HasSubstr("bus[0].name:"));
  EXPECT_THAT(Refusal("name: \"t\" bus { name: \"can@0\" }").what(), HasSubstr("may only have letters"));
  EXPECT_THAT(Refusal("name: \"t\" bus { name: \"can0\" bitrate: 5000 }").what(),
              HasSubstr("bus[0].bitrate: 5000 bit/s is outside 10000..1000000"));
  EXPECT_THAT(Refusal("name: \"t\" bus { name: \"can0\" bitrate: 2000000 }").what(),
              HasSubstr("bus[0].bitrate"));
  EXPECT_THAT(Refusal("name: \"t\" bus { name: \"a\" socketcand_port: 29536 }\nbus { name: \"b\" "
                      "socketcand_port: 29536 }")
                  .what(),
              HasSubstr(":2:17: bus[1].socketcand_port: port 29536 already serves bus a"));
}

// ---- devices ----------------------------------------------------------------------------------

TEST(TopologyDeviceTest, AnUnknownDeviceListsTheKnownOnes) {
  const TopologyError e = Refusal(R"(name: "t"
bus { name: "can0" }
node {
  name: "q"
  device: "quad"
  node_id: 5
  bus: "can0"
}
)");
  EXPECT_THAT(
      e.what(),
      HasSubstr("test.textproto:5:3: node[0].device: unknown device \"quad\" (known: quad-controller"));
}

TEST(TopologyDeviceTest, TheBusCountMustMatchTheDevicesPorts) {
  const TopologyError e = Refusal(R"(name: "t"
bus { name: "can0" }
bus { name: "can1" }
node { name: "q" device: "quad-controller" node_id: 5 bus: "can0" bus: "can1" }
)");
  EXPECT_THAT(
      e.what(),
      HasSubstr(
          ":4:55: node[0].bus[0]: quad-controller has 1 CAN port (CAN1), so node q needs 1 bus; 2 given"));
}

TEST(TopologyDeviceTest, NodeIdCountIsOneOrOnePerPort) {
  const TopologyError e = Refusal(R"(name: "t"
bus { name: "can0" }
node { name: "q" device: "quad-controller" node_id: 5 node_id: 6 bus: "can0" }
)");
  EXPECT_THAT(e.what(), HasSubstr("node[0].node_id[0]: give one node-ID, or one per port (quad-controller "
                                  "has 1 CAN port (CAN1)); 2 given"));
}

TEST(TopologyDeviceTest, DeviceOrEdsIsRequired) {
  const TopologyError e =
      Refusal("name: \"t\" bus { name: \"can0\" }\nnode { name: \"q\" node_id: 5 bus: \"can0\" }");
  EXPECT_THAT(e.what(), HasSubstr(":2:1: node[0]: node q needs device (a variant: quad-controller"));
}

TEST(TopologyDeviceTest, AMissingEdsNamesThePathItLookedFor) {
  const TopologyError e = Refusal(
      "name: \"t\" bus { name: \"can0\" }\nnode { name: \"q\" eds: \"eds/nope.eds\" node_id: 5 bus: \"can0\" "
      "}");
  EXPECT_THAT(e.what(), AllOf(HasSubstr(":2:18: node[0].eds: \"eds/nope.eds\": no such file (looked for "),
                              HasSubstr((kTopologies / "eds" / "nope.eds").string())));
}

TEST(TopologyDeviceTest, AnEdsThatIsNotAnEdsIsRefusedWithTheEdsReadersMessage) {
  // The topology file itself is not an EDS.
  const TopologyError e = Refusal(
      "name: \"t\" bus { name: \"can0\" }\nnode { name: \"q\" eds: \"demo.textproto\" node_id: 5 "
      "bus: \"can0\" }");
  EXPECT_THAT(e.what(), AllOf(HasSubstr("node[0].eds: "), HasSubstr("demo.textproto")));
}

TEST(TopologyDeviceTest, NodeNamesAreUniqueAndUsableAsFolderNames) {
  EXPECT_THAT(
      Refusal(kTwoQuads + "node { name: \"quad-5\" device: \"quad-controller\" node_id: 7 bus: \"can0\" }")
          .what(),
      HasSubstr(":5:8: node[2].name: node quad-5 is already defined (node[0], line 3)"));
  EXPECT_THAT(
      Refusal(kTwoQuads + "node { name: \"quad 7\" device: \"quad-controller\" node_id: 7 bus: \"can0\" }")
          .what(),
      HasSubstr("node[2].name: \"quad 7\" has a space"));
  EXPECT_THAT(
      Refusal(kTwoQuads + "node { name: \"a/b\" device: \"quad-controller\" node_id: 7 bus: \"can0\" }")
          .what(),
      HasSubstr("node[2].name: \"a/b\" has a slash"));
  EXPECT_THAT(Refusal(kTwoQuads + "node { device: \"quad-controller\" node_id: 7 bus: \"can0\" }").what(),
              HasSubstr(":5:1: node[2].name: required"));
}

TEST(TopologyDeviceTest, TheTopologyNeedsAUsableName) {
  EXPECT_THAT(Refusal("bus { name: \"can0\" }").what(), HasSubstr(":1:1: name: required"));
  EXPECT_THAT(Refusal("name: \"..\" bus { name: \"can0\" }").what(),
              HasSubstr("name: must be usable as a folder name"));
}

// ---- io and SDO writes ------------------------------------------------------------------------

TEST(TopologyIoTest, InputsAreCheckedAgainstTheDevicesSimulatedIo) {
  const auto node = [](const std::string& io) {
    return "name: \"t\" bus { name: \"can0\" }\nnode { name: \"q\" device: \"quad-controller\" node_id: 5 "
           "bus: \"can0\"\n" +
           io + "\n}";
  };
  EXPECT_NO_THROW(ParseTopology(node("io { key: \"IN1.voltage_mV\" value: \"3000\" }"), kFile));
  EXPECT_THAT(
      Refusal(node("io { key: \"IN9.voltage_mV\" value: \"3000\" }")).what(),
      AllOf(HasSubstr(":3:6: node[0].io[0].key: quad-controller has no signal \"IN9.voltage_mV\"; nearest: "
                      "IN1.voltage_mV, IN2.voltage_mV, IN3.voltage_mV (its inputs: "),
            HasSubstr("IN1.voltage_mV")));
  EXPECT_THAT(Refusal(node("io { key: \"IN1.voltage_mV\" value: \"40000\" }")).what(),
              HasSubstr(":3:28: node[0].io[0].value: IN1.voltage_mV: 40000 is out of range"));
  EXPECT_THAT(Refusal(node("io { key: \"OUT1.current_mA\" value: \"1\" }")).what(),
              HasSubstr("node[0].io[0].key: OUT1.current_mA is an output of quad-controller"));
  EXPECT_THAT(Refusal(node("io { key: \"voltage\" value: \"1\" }")).what(),
              HasSubstr("node[0].io[0].key: \"voltage\" is not a signal name (CHANNEL.quantity"));
  EXPECT_THAT(
      Refusal(node("io { key: \"IN1.level\" value: \"high\" }\nio { key: \"IN1.level\" value: \"low\" }"))
          .what(),
      HasSubstr(":4:6: node[0].io[1].key: \"IN1.level\" is already set by io[0]"));
}

TEST(TopologyIoTest, AGenericNodeHasNoSimulatedIo) {
  const TopologyError e = Refusal(R"(name: "t" bus { name: "can0" }
node { name: "dio" eds: "eds/canfleet-dio16.eds" node_id: 9 bus: "can0"
  io { key: "IN1.level" value: "high" } }
)");
  EXPECT_THAT(
      e.what(),
      HasSubstr(
          "node[0].io[0].key: node dio is a generic node (canfleet-dio16.eds): it has no simulated I/O"));
}

TEST(TopologySdoTest, WritesAreCheckedAgainstTheType) {
  const auto write = [](const std::string& sdo) {
    return "name: \"t\" bus { name: \"can0\" }\nnode { name: \"q\" device: \"quad-controller\" node_id: 5 "
           "bus: \"can0\"\n"
           "  sdo { " +
           sdo + " }\n}";
  };
  EXPECT_NO_THROW(ParseTopology(write("index: 0x1017 subindex: 0 type: \"u16\" value: \"500\""), kFile));
  EXPECT_THAT(Refusal(write("index: 0x1017 subindex: 0 type: \"u17\" value: \"500\"")).what(),
              HasSubstr(":3:35: node[0].sdo[0].type: \"u17\" is not a type (b i8 i16 i32 i64 u8 u16 u32 u64 "
                        "r32 r64 vs os d)"));
  EXPECT_THAT(Refusal(write("index: 0x1017 subindex: 0 type: \"u16\"")).what(),
              HasSubstr("node[0].sdo[0].value: required"));
  EXPECT_THAT(Refusal(write("index: 0x1017 subindex: 0 type: \"u16\" value: \"70000\"")).what(),
              AllOf(HasSubstr(":3:47: node[0].sdo[0].value: "), HasSubstr("70000")));
  EXPECT_THAT(Refusal(write("index: 0 type: \"u16\" value: \"1\"")).what(),
              HasSubstr("node[0].sdo[0].index: 0 is not an object index"));
  EXPECT_THAT(Refusal(write("index: 0x10000 type: \"u16\" value: \"1\"")).what(),
              HasSubstr("is not an object index"));
  EXPECT_THAT(Refusal(write("index: 0x1017 subindex: 256 type: \"u16\" value: \"1\"")).what(),
              HasSubstr("node[0].sdo[0].subindex: 256 is not a sub-index"));
  EXPECT_THAT(Refusal(write("index: 0x1017 type: \"u16\" value: \"1\" can: 2")).what(),
              HasSubstr("node[0].sdo[0].can: CAN2 does not exist: q has 1 CAN port (CAN1)"));
  EXPECT_THAT(Refusal(write("index: 0x1017 type: \"u16\" value: \"1\" port: 1")).what(),
              HasSubstr("node[0].sdo[0].port: CAN2 does not exist: q has 1 CAN port (CAN1)"));
}

TEST(TopologySdoTest, WritesAreCheckedAgainstTheDictionary) {
  const auto write = [](const std::string& sdo) {
    return "name: \"t\" bus { name: \"can0\" }\nnode { name: \"q\" device: \"quad-controller\" node_id: 5 "
           "bus: \"can0\"\n"
           "  sdo { " +
           sdo + " }\n}";
  };
  EXPECT_THAT(Refusal(write("index: 0x2345 type: \"u16\" value: \"1\"")).what(),
              HasSubstr("node[0].sdo[0].index: quad-controller has no object 2345h"));
  EXPECT_THAT(Refusal(write("index: 0x1017 subindex: 3 type: \"u16\" value: \"1\"")).what(),
              HasSubstr("node[0].sdo[0].subindex: quad-controller has no 1017h sub 3"));
  EXPECT_THAT(Refusal(write("index: 0x1018 subindex: 1 type: \"u32\" value: \"1\"")).what(),
              HasSubstr("node[0].sdo[0].index: 1018h sub 1 (Vendor-ID) of quad-controller is read-only"));
  EXPECT_THAT(
      Refusal(write("index: 0x1017 type: \"u32\" value: \"1\"")).what(),
      HasSubstr("node[0].sdo[0].type: u32 is 4 byte(s) but 1017h sub 0 (Producer Heartbeat Time) is 2"));
}

// ---- heartbeats -------------------------------------------------------------------------------

TEST(TopologyHeartbeatTest, ConsumersNameAnExistingNodeOnTheSameBus) {
  const auto with = [](const std::string& consumer) {
    return kTwoQuads +
           "node { name: \"quad-7\" device: \"quad-controller\" node_id: 7 bus: \"can0\"\n"
           "  heartbeat { consumer { " +
           consumer + " } } }\n";
  };
  const LoadedTopology ok = Load(with("node: \"quad-5\" timeout_ms: 1500"));
  EXPECT_EQ(ok.spec.node(2).heartbeat().consumer(0).node_id(), 5u);  // filled in from the name
  EXPECT_THAT(Refusal(with("node: \"quad-9\" timeout_ms: 1500")).what(),
              HasSubstr(":6:26: node[2].heartbeat.consumer[0].node: unknown node \"quad-9\""));
  EXPECT_THAT(Refusal(with("node: \"quad-7\" timeout_ms: 1500")).what(),
              HasSubstr("cannot consume its own heartbeat"));
  EXPECT_THAT(Refusal(with("node: \"quad-5\"")).what(),
              HasSubstr("node[2].heartbeat.consumer[0].timeout_ms: required, > 0"));
  EXPECT_THAT(Refusal(with("node: \"quad-5\" node_id: 6 timeout_ms: 100")).what(),
              HasSubstr("consumer[0].node_id: node_id 6 is not quad-5's node-ID (5)"));
  EXPECT_THAT(Refusal(with("timeout_ms: 100")).what(),
              HasSubstr("consumer[0]: give node (a node of the topology) or node_id"));
  EXPECT_THAT(Refusal(with("node_id: 200 timeout_ms: 100")).what(),
              HasSubstr("consumer[0].node_id: 200 is not a node-ID"));
  EXPECT_NO_THROW(ParseTopology(with("node_id: 100 timeout_ms: 100"), kFile));  // a node outside the topology
}

TEST(TopologyHeartbeatTest, NodesOnOtherBusesCannotBeConsumed) {
  const TopologyError e = Refusal(R"(name: "t" bus { name: "can0" } bus { name: "can1" }
node { name: "a" device: "quad-controller" node_id: 5 bus: "can0" }
node { name: "b" device: "quad-controller" node_id: 6 bus: "can1"
  heartbeat { consumer { node: "a" timeout_ms: 1000 } } }
)");
  EXPECT_THAT(e.what(), HasSubstr("node[1].heartbeat.consumer[0].node: b and a share no bus"));
}

TEST(TopologyHeartbeatTest, TheTimeoutMustExceedTheProducersPeriod) {
  const TopologyError e = Refusal(R"(name: "t" bus { name: "can0" }
node { name: "a" device: "quad-controller" node_id: 5 bus: "can0" heartbeat { producer_ms: 500 } }
node { name: "b" device: "quad-controller" node_id: 6 bus: "can0"
  heartbeat { consumer { node: "a" timeout_ms: 500 } } }
)");
  EXPECT_THAT(e.what(), HasSubstr("timeout_ms: 500 ms is not longer than a's heartbeat period (500 ms)"));
}

TEST(TopologyHeartbeatTest, ConsumersFitTheDevices1016h) {
  std::string consumers;
  for (int id = 10; id < 15; ++id)
    consumers += "consumer { node_id: " + std::to_string(id) + " timeout_ms: 1000 } ";
  const TopologyError e = Refusal(kTwoQuads +
                                  "node { name: \"q\" device: \"quad-controller\" node_id: 7 bus: \"can0\"\n"
                                  "  heartbeat { " +
                                  consumers + "} }");
  EXPECT_THAT(e.what(), HasSubstr("node[2].heartbeat.consumer[4]: quad-controller has 4 heartbeat consumer "
                                  "entries (1016h); 5 given"));
  const TopologyError twice =
      Refusal(kTwoQuads +
              "node { name: \"q\" device: \"quad-controller\" node_id: 7 bus: \"can0\"\n"
              "  heartbeat { consumer { node: \"quad-5\" timeout_ms: 900 } "
              "consumer { node_id: 5 timeout_ms: 1000 } } }");
  EXPECT_THAT(twice.what(), HasSubstr("consumer[1]: node-ID 5 is already consumed by consumer[0]"));
}

// ---- scenario ---------------------------------------------------------------------------------

TEST(TopologyScenarioTest, StepsReferToNodesAndBusesOfTheTopology) {
  EXPECT_THAT(Refusal(kTwoQuads + "scenario { at_ms: 10 inject { kind: BUS_OFF node: \"quad-9\" } }").what(),
              HasSubstr(":5:45: scenario[0].inject.node: unknown node \"quad-9\""));
  EXPECT_THAT(Refusal(kTwoQuads + "scenario { inject { kind: DROP bus: \"can7\" } }").what(),
              HasSubstr("scenario[0].inject.bus: unknown bus \"can7\""));
  EXPECT_THAT(Refusal(kTwoQuads + "scenario { inject { kind: BUS_OFF } }").what(),
              HasSubstr("scenario[0].inject.node: required: BUS_OFF needs the node"));
  EXPECT_THAT(Refusal(kTwoQuads + "scenario { inject { node: \"quad-5\" } }").what(),
              HasSubstr("scenario[0].inject.kind: required"));
  EXPECT_THAT(Refusal(kTwoQuads + "scenario { at_ms: 5 }").what(),
              HasSubstr("scenario[0]: a step needs an action"));
  EXPECT_THAT(
      Refusal(kTwoQuads + "scenario { io { node: \"quad-5\" name: \"IN1.voltage_mV\" value: \"99999\" } }")
          .what(),
      HasSubstr("scenario[0].io.value: IN1.voltage_mV: 99999 is out of range"));
  EXPECT_THAT(Refusal(kTwoQuads + "scenario { nmt { node: \"quad-5\" } }").what(),
              HasSubstr("scenario[0].nmt.action: required"));
  EXPECT_THAT(Refusal(kTwoQuads + "scenario { nmt { action: NMT_START node: \"x\" } }").what(),
              HasSubstr("scenario[0].nmt.node: unknown node \"x\""));
  EXPECT_THAT(
      Refusal(kTwoQuads + "scenario { sdo { node: \"quad-5\" index: 0x1017 type: \"u8\" value: \"1\" } }")
          .what(),
      HasSubstr("scenario[0].sdo.type: u8 is 1 byte(s) but 1017h sub 0"));
}

TEST(TopologyScenarioTest, FaultSpecsAreSane) {
  EXPECT_THAT(Refusal(kTwoQuads + "scenario { inject { kind: RPDO_TIMEOUT node: \"quad-6\" } }").what(),
              HasSubstr("scenario[0].inject.cob_id: required: RPDO_TIMEOUT needs the COB-ID"));
  EXPECT_THAT(Refusal(kTwoQuads + "scenario { inject { kind: DROP probability: 1.5 } }").what(),
              HasSubstr("scenario[0].inject.probability: 1.500000 is outside 0..1"));
  EXPECT_THAT(Refusal(kTwoQuads + "scenario { inject { kind: DROP cob_id: 0x800 } }").what(),
              HasSubstr("scenario[0].inject.cob_id: 0x800 does not fit a 11-bit identifier"));
  EXPECT_NO_THROW(
      ParseTopology(kTwoQuads + "scenario { inject { kind: DROP cob_id: 0x800 extended: true } }", kFile));
  EXPECT_THAT(Refusal(kTwoQuads +
                      "scenario { inject { kind: PARTITION bus: \"can0\" groups { nodes: \"quad-5\" } } }")
                  .what(),
              HasSubstr("scenario[0].inject.groups[0]: PARTITION needs at least 2 groups of nodes; 1 given"));
  EXPECT_THAT(
      Refusal(
          kTwoQuads +
          "scenario { inject { kind: PARTITION groups { nodes: \"quad-5\" } groups { nodes: \"quad-6\" } } }")
          .what(),
      HasSubstr("scenario[0].inject.bus: required: PARTITION without node"));
  EXPECT_THAT(
      Refusal(
          kTwoQuads +
          "scenario { inject { kind: PARTITION bus: \"can0\" groups { nodes: \"quad-5\" } groups { nodes: "
          "\"quad-5\" } } }")
          .what(),
      HasSubstr("scenario[0].inject.groups[1].nodes: node quad-5 is already in groups[0]"));
  EXPECT_NO_THROW(ParseTopology(kTwoQuads + "scenario { inject { kind: PARTITION bus: \"can0\" groups { "
                                            "nodes: \"quad-5\" } groups { nodes: \"quad-6\" } } }",
                                kFile));
  EXPECT_THAT(Refusal(kTwoQuads + "scenario { inject { kind: DELAY } }").what(),
              HasSubstr("DELAY needs delay_ms or jitter_ms"));
}

// What each kind takes comes from one table (orchestrator/control/fault_kinds.hpp): an option a
// kind does not take is refused with what it takes, never ignored; bus-off held for a duration is
// a form of its own, exclusive with manual recovery.
TEST(TopologyScenarioTest, OptionsAKindDoesNotTakeAreRefused) {
  EXPECT_THAT(
      Refusal(kTwoQuads + "scenario { inject { kind: BUS_OFF node: \"quad-5\" cob_id: 0x185 } }").what(),
      HasSubstr("scenario[0].inject.cob_id: cob_id does not apply to BUS_OFF (it takes node, bus, "
                "duration_ms, manual_recovery, label)"));
  EXPECT_THAT(
      Refusal(
          kTwoQuads +
          "scenario { inject { kind: BUS_OFF node: \"quad-5\" manual_recovery: true duration_ms: 2000 } }")
          .what(),
      HasSubstr("scenario[0].inject.manual_recovery: duration_ms and manual_recovery are two forms of "
                "BUS_OFF: give one"));
  EXPECT_THAT(Refusal(kTwoQuads + "scenario { inject { kind: CORRUPT receivers: \"quad-6\" } }").what(),
              HasSubstr("scenario[0].inject.receivers: receivers does not apply to CORRUPT"));
  EXPECT_THAT(
      Refusal(kTwoQuads + "scenario { inject { kind: KILL node: \"quad-5\" bus: \"can0\" } }").what(),
      HasSubstr("scenario[0].inject.bus: bus does not apply to KILL (it takes node, duration_ms, label)"));
  EXPECT_THAT(Refusal(kTwoQuads + "scenario { inject { kind: DROP mask: 0x780 } }").what(),
              HasSubstr("scenario[0].inject.mask: mask needs cob_id, the identifier it masks"));
  EXPECT_THAT(
      Refusal(kTwoQuads + "scenario { inject { kind: RESTART node: \"quad-5\" duration_ms: 100 } }").what(),
      HasSubstr("scenario[0].inject.duration_ms: duration_ms does not apply to RESTART"));

  const LoadedTopology held =
      Load(kTwoQuads +
           "scenario { inject { kind: BUS_OFF node: \"quad-5\" duration_ms: 2000 } }\n"
           "scenario { inject { kind: KILL node: \"quad-6\" } }\n");
  EXPECT_EQ(held.spec.scenario(0).inject().bus(), "can0");
  EXPECT_EQ(held.spec.scenario(1).inject().bus(), "") << "a process fault takes no bus: none is filled in";
}

TEST(TopologyScenarioTest, LabelsAreUniqueAndClearedOnlyAfterTheirInjection) {
  const std::string inject =
      "scenario { at_ms: 1000 inject { kind: BUS_OFF node: \"quad-5\" label: \"off\" } }\n";
  EXPECT_NO_THROW(
      ParseTopology(kTwoQuads + inject + "scenario { at_ms: 2000 clear { label: \"off\" } }", kFile));
  // In file order it comes first, but it runs at 500 ms: before the injection.
  EXPECT_THAT(Refusal(kTwoQuads + inject + "scenario { at_ms: 500 clear { label: \"off\" } }").what(),
              HasSubstr(":6:31: scenario[1].clear.label: no earlier step injects a fault labelled \"off\""));
  EXPECT_THAT(Refusal(kTwoQuads + inject + inject).what(),
              HasSubstr("scenario[1].inject.label: label \"off\" is already used"));
  EXPECT_THAT(Refusal(kTwoQuads + "scenario { clear { fault_id: 3 } }").what(),
              HasSubstr("scenario[0].clear.fault_id: fault ids are given out at run time"));
  EXPECT_NO_THROW(ParseTopology(kTwoQuads + "scenario { clear { } }", kFile));  // clears every fault
}

// A repeating scenario's next run injects its labels again: it must have clear()ed them.
TEST(TopologyScenarioTest, ARepeatingScenarioClearsWhatItInjects) {
  const std::string inject =
      "scenario { at_ms: 1000 inject { kind: HEARTBEAT_LOSS node: \"quad-5\" label: \"hb\" } }\n";
  const std::string repeat = "scenario_repeat_ms: 5000\n";
  EXPECT_NO_THROW(
      ParseTopology(kTwoQuads + repeat + inject + "scenario { at_ms: 2000 clear { label: \"hb\" } }", kFile));
  EXPECT_NO_THROW(ParseTopology(kTwoQuads + repeat + inject + "scenario { at_ms: 2000 clear { } }", kFile));
  // A bus-off that recovers on its own ends by itself (one-shot): nothing to clear.
  EXPECT_NO_THROW(ParseTopology(
      kTwoQuads + repeat + "scenario { inject { kind: BUS_OFF node: \"quad-5\" label: \"off\" } }", kFile));
  EXPECT_THAT(
      Refusal(kTwoQuads + repeat + inject).what(),
      HasSubstr("scenario[0].inject.label: the scenario repeats (scenario_repeat_ms) but never clears "
                "\"hb\""));
  EXPECT_THAT(Refusal(kTwoQuads + repeat).what(),
              HasSubstr("scenario_repeat_ms: there is no scenario to repeat"));
  EXPECT_NO_THROW(ParseTopology(kTwoQuads + inject, kFile));  // once: a fault may stay
}

TEST(TopologyScenarioTest, ProcessFaultsCannotReachExternalNodes) {
  const TopologyError e = Refusal(R"(name: "t" bus { name: "can0" }
node { name: "x" device: "quad-controller" node_id: 5 bus: "can0" external: true }
scenario { inject { kind: KILL node: "x" } }
)");
  EXPECT_THAT(e.what(), HasSubstr("scenario[0].inject.node: node x is external"));
}

// ---- defaults and paths -----------------------------------------------------------------------

TEST(TopologyDefaultsTest, DefaultsAreAppliedSoTheConsumerNeverGuesses) {
  const LoadedTopology t = Load(kTwoQuads + R"(bus { name: "can1" }
node { name: "dio" eds: "eds/canfleet-dio16.eds" node_id: 9 bus: "can1" }
scenario { inject { kind: HEARTBEAT_LOSS node: "quad-5" } }
)");
  const Topology& s = t.spec;
  EXPECT_EQ(t.file, kFile);
  EXPECT_EQ(s.bus(0).bitrate(), 250000u);
  EXPECT_EQ(s.bus(1).bitrate(), 500000u);
  EXPECT_EQ(s.orchestrator().control(), "tcp://127.0.0.1:29700");
  ASSERT_EQ(s.orchestrator().listen_size(), 1);
  EXPECT_EQ(s.orchestrator().listen(0), "tcp://127.0.0.1:29600");
  ASSERT_TRUE(s.orchestrator().has_start_nodes());
  EXPECT_TRUE(s.orchestrator().start_nodes());
  const fs::path root = kTopologies / ".canfleet" / "t";
  EXPECT_EQ(s.orchestrator().state_root(), root.string());
  EXPECT_EQ(s.node(0).state_dir(), (root / "quad-5").string());
  EXPECT_EQ(s.node(2).state_dir(), (root / "dio").string());
  EXPECT_EQ(s.node(0).restart().backoff_ms(), 500u);
  EXPECT_EQ(s.node(0).restart().policy(), Restart::NEVER);
  EXPECT_EQ(s.node(0).log_level(), "info");
  ASSERT_EQ(s.node(0).node_id_size(), 1);
  EXPECT_EQ(s.node(2).eds(), kDioEds.string());
  EXPECT_EQ(s.scenario(0).inject().bus(), "can0");  // the node's bus
}

TEST(TopologyDefaultsTest, GivenValuesAreKept) {
  const LoadedTopology t = Load(R"(name: "t"
orchestrator { control: "tcp://127.0.0.1:0" listen: "unix:///tmp/x.sock" listen: "tcp://127.0.0.1:0" start_nodes: false }
bus { name: "can0" }
node { name: "q" device: "quad-controller" node_id: 5 bus: "can0" log_level: "debug"
  restart { policy: ON_FAILURE backoff_ms: 2000 } }
)");
  EXPECT_EQ(t.spec.orchestrator().control(), "tcp://127.0.0.1:0");
  EXPECT_EQ(t.spec.orchestrator().listen_size(), 2);
  EXPECT_FALSE(t.spec.orchestrator().start_nodes());
  EXPECT_EQ(t.spec.node(0).log_level(), "debug");
  EXPECT_EQ(t.spec.node(0).restart().backoff_ms(), 2000u);
}

TEST(TopologyDefaultsTest, OrchestratorSettingsAreChecked) {
  EXPECT_THAT(Refusal("name: \"t\"\norchestrator { control: \"http://x\" }\nbus { name: \"can0\" }").what(),
              HasSubstr(":2:16: orchestrator.control: "));
  EXPECT_THAT(
      Refusal("name: \"t\"\norchestrator { listen: \"tcp://127.0.0.1:1\"\nlisten: \"tcp://127.0.0.1:1\" "
              "}\nbus { name: \"can0\" }")
          .what(),
      HasSubstr(":3:1: orchestrator.listen[1]: \"tcp://127.0.0.1:1\" is already listed as listen[0]"));
  EXPECT_THAT(
      Refusal(kTwoQuads +
              "node { name: \"q\" device: \"quad-controller\" node_id: 7 bus: \"can0\" log_level: \"loud\" }")
          .what(),
      HasSubstr("node[2].log_level: \"loud\" is not a log level"));
  EXPECT_THAT(
      Refusal(kTwoQuads +
              "node { name: \"q\" device: \"quad-controller\" node_id: 7 bus: \"can0\" external: true "
              "restart { policy: ON_FAILURE } }")
          .what(),
      HasSubstr("node[2].restart.policy: node q is external"));
}

TEST(TopologyPathsTest, RelativePathsAreRelativeToTheTopologysFolder) {
  const fs::path file = kTopologies / "examples" / "t.textproto";
  const LoadedTopology t = Load(R"(name: "t"
orchestrator { state_root: "../run/state" }
bus { name: "can0" }
node { name: "a" eds: "../eds/canfleet-dio16.eds" node_id: 5 bus: "can0" }
node { name: "b" device: "quad-controller" node_id: 6 bus: "can0" state_dir: "b-state" }
node { name: "c" device: "quad-controller" node_id: 7 bus: "can0" state_dir: "/var/tmp/c" }
)",
                                file);
  EXPECT_EQ(t.file, file);
  EXPECT_EQ(t.spec.orchestrator().state_root(), (kTopologies / "run" / "state").string());
  EXPECT_EQ(t.spec.node(0).eds(), kDioEds.string());
  EXPECT_EQ(t.spec.node(0).state_dir(), (kTopologies / "run" / "state" / "a").string());
  EXPECT_EQ(t.spec.node(1).state_dir(), (kTopologies / "examples" / "b-state").string());
  EXPECT_EQ(t.spec.node(2).state_dir(), "/var/tmp/c");
}

TEST(TopologyPathsTest, ARelativeFileNameIsMadeAbsolute) {
  const fs::path cwd = fs::current_path();
  fs::current_path(kTopologies);
  LoadedTopology t;
  try {
    t = ParseTopology(
        "name: \"t\" bus { name: \"can0\" }\nnode { name: \"a\" eds: \"eds/canfleet-dio16.eds\" node_id: 5 "
        "bus: \"can0\" }",
        "x.textproto");
  } catch (...) {
    fs::current_path(cwd);
    throw;
  }
  fs::current_path(cwd);
  EXPECT_EQ(t.file, kTopologies / "x.textproto");
  EXPECT_EQ(t.spec.node(0).eds(), kDioEds.string());
}

TEST(TopologyPathsTest, TwoNodesCannotShareAStateFolder) {
  const TopologyError e = Refusal(R"(name: "t" bus { name: "can0" }
node { name: "a" device: "quad-controller" node_id: 5 bus: "can0" state_dir: "s" }
node { name: "b" device: "quad-controller" node_id: 6 bus: "can0" state_dir: "./s" }
)");
  EXPECT_THAT(e.what(), HasSubstr(":3:67: node[1].state_dir: folder "));
  EXPECT_THAT(e.what(), HasSubstr("is already the state folder of node a"));
}

// ---- files ------------------------------------------------------------------------------------

class TopologyFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("canfleet-topology-test-" + std::to_string(::getpid()));
    fs::create_directories(dir_ / "eds");
    fs::copy_file(kDioEds, dir_ / "eds" / "dio.eds");
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path Write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
    return dir_ / name;
  }
  fs::path dir_;
};

TEST_F(TopologyFileTest, AFileLoadsWithItsFolderAsBase) {
  const fs::path file = Write("f.textproto",
                              "name: \"f\" bus { name: \"can0\" }\nnode { name: \"d\" eds: \"eds/dio.eds\" "
                              "node_id: 5 bus: \"can0\" }\n");
  const LoadedTopology t = LoadTopology(file);
  EXPECT_EQ(t.file, file);
  EXPECT_EQ(t.spec.node(0).eds(), (dir_ / "eds" / "dio.eds").string());
  EXPECT_EQ(t.spec.orchestrator().state_root(), (dir_ / ".canfleet" / "f").string());
}

TEST_F(TopologyFileTest, ErrorsNameTheFileAsGiven) {
  const fs::path file =
      Write("bad.textproto", "name: \"f\"\nbus { name: \"can0\" }\nnode { name: \"d\" device: \"x\" }\n");
  try {
    (void)LoadTopology(file);
    FAIL() << "loaded";
  } catch (const TopologyError& e) {
    EXPECT_THAT(e.what(), StartsWith(file.string() + ":3:18: node[0].device: unknown device \"x\""));
    EXPECT_EQ(e.file(), file.string());
  }
}

TEST_F(TopologyFileTest, AMissingFileIsNamed) {
  const fs::path file = dir_ / "nope.textproto";
  try {
    (void)LoadTopology(file);
    FAIL() << "loaded";
  } catch (const TopologyError& e) {
    EXPECT_EQ(std::string(e.what()), file.string() + ": no such file");
    EXPECT_EQ(e.line(), 0);
  }
  try {
    (void)LoadTopology(dir_);
    FAIL() << "loaded a folder";
  } catch (const TopologyError& e) {
    EXPECT_THAT(e.what(), HasSubstr("is a folder"));
  }
}

TEST_F(TopologyFileTest, DcfFilesMustExistAndParse) {
  const std::string base =
      "name: \"f\" bus { name: \"can0\" }\nnode { name: \"d\" eds: \"eds/dio.eds\" node_id: 5 bus: \"can0\" ";
  EXPECT_THAT(Refusal(base + "dcf: \"d.dcf\" }", dir_ / "x.textproto").what(),
              HasSubstr("node[0].dcf: \"d.dcf\": no such file"));
  Write("d.dcf", "[1000]\nthis is not a DCF\n");
  EXPECT_THAT(Refusal(base + "dcf: \"d.dcf\" }", dir_ / "x.textproto").what(), HasSubstr("node[0].dcf: "));
  fs::copy_file(kDioEds, dir_ / "ok.dcf");
  const LoadedTopology t = Load(base + "dcf: \"ok.dcf\" }", dir_ / "x.textproto");
  EXPECT_EQ(t.spec.node(0).dcf(), (dir_ / "ok.dcf").string());
}

// ---- what ships ---------------------------------------------------------------------------------

TEST(ShippedTopologiesTest, EveryShippedTopologyLoadsWithoutWarnings) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::recursive_directory_iterator(kTopologies)) {
    if (entry.is_regular_file() && entry.path().extension() == ".textproto") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  EXPECT_GE(files.size(), 6u);
  for (const fs::path& file : files) {
    SCOPED_TRACE(file.string());
    try {
      const LoadedTopology t = LoadTopology(file);
      EXPECT_FALSE(t.spec.name().empty());
      EXPECT_GE(t.spec.bus_size(), 1);
      // What we ship works as written (topologies/README.md "What loading warns about").
      for (const TopologyWarning& w : t.warnings)
        ADD_FAILURE() << w.Message();
      EXPECT_EQ(t.loads.size(), static_cast<std::size_t>(t.spec.bus_size()));
    } catch (const TopologyError& e) {
      ADD_FAILURE() << e.what();
    }
  }
}

TEST(ShippedTopologiesTest, TheDemoHasAQuadChainAndAGenericNode) {
  const LoadedTopology t = LoadTopology(kTopologies / "demo.textproto");
  int quads = 0;
  int generic = 0;
  for (const Node& node : t.spec.node()) {
    if (node.device() == "quad-controller" && node.bus(0) == "can0") ++quads;
    if (node.device().empty() && !node.eds().empty()) ++generic;
  }
  EXPECT_GE(quads, 3);
  EXPECT_EQ(generic, 1);
  EXPECT_EQ(t.spec.bus(0).bitrate(), 250000u);
}

TEST(ShippedTopologiesTest, EachFaultExampleInjectsAndClearsItsFault) {
  for (const auto& [file, kind] : {std::pair{"heartbeat-loss.textproto", control::HEARTBEAT_LOSS},
                                   std::pair{"rpdo-timeout.textproto", control::RPDO_TIMEOUT},
                                   std::pair{"bus-off.textproto", control::BUS_OFF}}) {
    SCOPED_TRACE(file);
    const LoadedTopology t = LoadTopology(kTopologies / "examples" / file);
    bool injected = false;
    bool cleared = false;
    for (const Step& step : t.spec.scenario()) {
      if (step.has_inject() && step.inject().kind() == kind) injected = true;
      if (step.has_clear() && injected) cleared = true;
    }
    EXPECT_TRUE(injected);
    EXPECT_TRUE(cleared);
  }
}

// Issue 18: the demo (and its container twin) runs the data logger on both buses, with the TC
// limits of its README's demo configuration: they default to 0 and trip at room temperature
// (UMAX181001 §3.4.22-3.4.26).
TEST(ShippedTopologiesTest, TheDemosRunTheDataLoggerOnTwoBusesWithItsTcLimitsSet) {
  for (const char* file : {"demo.textproto", "docker.textproto"}) {
    SCOPED_TRACE(file);
    const LoadedTopology t = LoadTopology(kTopologies / file);
    const Node* logger = nullptr;
    for (const Node& node : t.spec.node())
      if (node.device() == "datalogger-tc-analog") logger = &node;
    ASSERT_NE(logger, nullptr);
    ASSERT_EQ(logger->bus_size(), 2);
    EXPECT_NE(logger->bus(0), logger->bus(1));
    for (const std::uint32_t index : {0x2171u, 0x2173u}) {
      int subs = 0;
      for (const auto& write : logger->sdo())
        if (write.index() == index && write.value() != "0") ++subs;
      EXPECT_EQ(subs, 4) << std::hex << index;
    }
  }
}

}  // namespace
}  // namespace canfleet::topology
