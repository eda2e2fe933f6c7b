// What loading warns about (topologies/README.md "What loading warns about"): configurations that
// load but cannot work — heartbeat consumers of silent or absent producers, RPDO deadlines nothing
// feeds, PDO lengths that differ, SYNC-driven TPDOs without SYNC, two producers of one COB-ID — and
// the periodic load each bus is offered, with its warning above 100 %.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "orchestrator/topology/topology_loader.hpp"

namespace canfleet::topology {
namespace {

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::IsEmpty;
using ::testing::SizeIs;
using ::testing::StartsWith;

const fs::path kTopologies = fs::path(CANFLEET_SOURCE_DIR) / "topologies";
const fs::path kFile = kTopologies / "t.textproto";

LoadedTopology Load(const std::string& text) {
  try {
    return ParseTopology(text, kFile);
  } catch (const TopologyError& e) {
    ADD_FAILURE() << e.what();
    throw;
  }
}

std::vector<std::string> Messages(const LoadedTopology& t) {
  std::vector<std::string> out;
  for (const TopologyWarning& w : t.warnings)
    out.push_back(w.Message());
  return out;
}

// quad-5 on line 3, quad-6 from line 4 on; each test appends quad-6's body and what follows.
const std::string kHead = R"(name: "t"
bus { name: "can0" bitrate: 250000 }
node { name: "quad-5" device: "quad-controller" node_id: 5 bus: "can0" heartbeat { producer_ms: 200 } }
)";

// quad-6's RPDO1 (1400h, 8 bytes: 7330h sub 1-4, AX020506 §3.1.1) on `cob_id`, with a deadline.
std::string Rpdo1(const std::string& cob_id, int deadline_ms) {
  return R"(node { name: "quad-6" device: "quad-controller" node_id: 6 bus: "can0"
  sdo { index: 0x1400 subindex: 1 type: "u32" value: "0x80000185" }
  sdo { index: 0x1400 subindex: 1 type: "u32" value: ")" +
         cob_id + R"(" }
  sdo { index: 0x1400 subindex: 5 type: "u16" value: ")" +
         std::to_string(deadline_ms) + R"(" } }
)";
}

// ---- heartbeat consumers (CiA 301 §7.2.8.3.2.2: monitoring starts with the first heartbeat) ----

TEST(HeartbeatWarningTest, AConsumerOfANodeThatSendsNoHeartbeatIsWarnedAtTheConsumer) {
  // quad-7 keeps the Quad's 1017h default 0 (AX020506 §3.1.1 object table): it never sends one.
  const LoadedTopology t =
      Load(kHead + R"(node { name: "quad-7" device: "quad-controller" node_id: 7 bus: "can0" }
node { name: "quad-6" device: "quad-controller" node_id: 6 bus: "can0"
  heartbeat { consumer { node: "quad-7" timeout_ms: 1000 } } }
)");
  ASSERT_THAT(t.warnings, SizeIs(1));
  const TopologyWarning& w = t.warnings[0];
  EXPECT_EQ(w.line, 6);
  EXPECT_EQ(w.column, 15);
  EXPECT_EQ(w.field, "node[2].heartbeat.consumer[0]");
  EXPECT_THAT(w.Message(), StartsWith(kFile.string() + ":6:15: warning: node[2].heartbeat.consumer[0]: "));
  EXPECT_THAT(w.reason,
              AllOf(HasSubstr("quad-6 consumes the heartbeat of quad-7 (node-ID 7 on can0)"),
                    HasSubstr("its 1017h is 0 (its default"), HasSubstr("no loss is ever reported")));
}

TEST(HeartbeatWarningTest, AConsumerOfAProducingNodeDoesNotWarn) {
  const LoadedTopology t =
      Load(kHead + R"(node { name: "quad-6" device: "quad-controller" node_id: 6 bus: "can0"
  heartbeat { producer_ms: 200 consumer { node: "quad-5" timeout_ms: 1000 } } }
node { name: "quad-7" device: "quad-controller" node_id: 7 bus: "can0"
  heartbeat { consumer { node_id: 6 timeout_ms: 600 } } }
)");
  EXPECT_THAT(Messages(t), IsEmpty());
}

TEST(HeartbeatWarningTest, AConsumerOfANodeIdNoNodeHasOnTheBusIsWarned) {
  const LoadedTopology t =
      Load(kHead + R"(node { name: "quad-6" device: "quad-controller" node_id: 6 bus: "can0"
  heartbeat { consumer { node_id: 42 timeout_ms: 1000 } } }
)");
  ASSERT_THAT(t.warnings, SizeIs(1));
  EXPECT_EQ(t.warnings[0].field, "node[1].heartbeat.consumer[0]");
  EXPECT_EQ(t.warnings[0].line, 5);
  EXPECT_THAT(t.warnings[0].reason, HasSubstr("no node of the topology has that node-ID on bus can0"));
}

// A period set by an SDO write (or the EDS default) is not checked by loading, which only compares
// the consumer time with heartbeat.producer_ms: a consumer time not above it reports a loss of a
// running producer.
TEST(HeartbeatWarningTest, AConsumerTimeNotLongerThanTheProducersPeriodIsWarned) {
  const LoadedTopology t = Load(R"(name: "t"
bus { name: "can0" bitrate: 250000 }
node { name: "quad-5" device: "quad-controller" node_id: 5 bus: "can0"
  sdo { index: 0x1017 subindex: 0 type: "u16" value: "500" } }
node { name: "quad-6" device: "quad-controller" node_id: 6 bus: "can0"
  heartbeat { consumer { node: "quad-5" timeout_ms: 400 } } }
)");
  ASSERT_THAT(t.warnings, SizeIs(1));
  EXPECT_THAT(t.warnings[0].reason,
              AllOf(HasSubstr("within 400 ms, but it comes every 500 ms (1017h, sdo[0])"),
                    HasSubstr("reported while the producer runs")));
}

// ---- RPDO deadlines (CiA 301 §7.5.2.35: the event timer of an RPDO is its deadline, started by a
// reception) -------------------------------------------------------------------------------------

TEST(PdoWarningTest, AnRpdoDeadlineOnACobIdNoNodeSendsIsWarnedWhereTheDeadlineIsSet) {
  const LoadedTopology t = Load(kHead + Rpdo1("0x190", 500));
  ASSERT_THAT(t.warnings, SizeIs(1));
  const TopologyWarning& w = t.warnings[0];
  EXPECT_EQ(w.field, "node[1].sdo[2].value");
  EXPECT_EQ(w.line, 7);
  EXPECT_THAT(w.reason, AllOf(HasSubstr("quad-6 RPDO1 (1400h) has a 500 ms deadline (1400h sub 5, sdo[2]) on "
                                        "COB-ID 190h, which nothing sends"),
                              HasSubstr("no RPDO timeout is ever reported")));
}

TEST(PdoWarningTest, AnRpdoFedByAMatchingTpdoMoreOftenThanItsDeadlineDoesNotWarn) {
  // quad-5's TPDO1: 185h, 8 bytes (7100h sub 1-4), every 100 ms (AX020506 §3.1.1).
  EXPECT_THAT(Messages(Load(kHead + Rpdo1("0x185", 500))), IsEmpty());
}

TEST(PdoWarningTest, AnRpdoDeadlineNotLongerThanTheTpdosPeriodIsWarned) {
  const LoadedTopology t = Load(kHead + Rpdo1("0x185", 100));
  ASSERT_THAT(t.warnings, SizeIs(1));
  EXPECT_THAT(
      t.warnings[0].reason,
      HasSubstr("quad-5 TPDO1 (1800h) sends it every 100 ms: the deadline expires between two frames"));
}

TEST(PdoWarningTest, AnRpdoFedOnlyByANodeThatIsNeverStartedIsWarned) {
  // PDOs run in operational only (CiA 301 §7.3.2.2 table 51): quad-5 stays pre-operational.
  const std::string topology = R"(name: "t"
orchestrator { start_nodes: false }
bus { name: "can0" bitrate: 250000 }
node { name: "quad-5" device: "quad-controller" node_id: 5 bus: "can0" }
)" + Rpdo1("0x185", 500);
  const LoadedTopology t = Load(topology + R"(scenario { nmt { action: NMT_START node: "quad-6" } }
)");
  ASSERT_THAT(t.warnings, SizeIs(1));
  EXPECT_THAT(
      t.warnings[0].reason,
      HasSubstr("quad-5 TPDO1 (1800h) has it, but quad-5 is never started (orchestrator.start_nodes is "
                "false and no scenario NMT start names it)"));
  // An NMT start of every node starts quad-5 too.
  EXPECT_THAT(Messages(Load(topology + "scenario { nmt { action: NMT_START } }\n")), IsEmpty());
}

TEST(PdoWarningTest, AnRpdoWhoseMappingLengthDiffersFromItsTpdoIsWarned) {
  // RPDO2 maps 6200h sub 1 (1 byte); quad-5's TPDO2 (285h) sends 7100h sub 5-6 (4 bytes): CiA 301
  // §7.2.2.2, an RPDO length error (EMCY 8210h/8220h) at every frame.
  const LoadedTopology t =
      Load(kHead + R"(node { name: "quad-6" device: "quad-controller" node_id: 6 bus: "can0"
  sdo { index: 0x1401 subindex: 1 type: "u32" value: "0x80000285" }
  sdo { index: 0x1401 subindex: 1 type: "u32" value: "0x285" } }
)");
  ASSERT_THAT(t.warnings, SizeIs(1));
  EXPECT_EQ(t.warnings[0].field, "node[1].sdo[1].value");
  EXPECT_THAT(
      t.warnings[0].reason,
      HasSubstr("quad-6 RPDO2 (1401h) maps 1 byte, but quad-5 TPDO2 (1801h) sends 4 bytes on COB-ID 285h"));
}

// ---- TPDOs ----------------------------------------------------------------------------------------

TEST(PdoWarningTest, TwoTpdosWithOneCobIdOnABusAreWarned) {
  const LoadedTopology t =
      Load(kHead + R"(node { name: "quad-6" device: "quad-controller" node_id: 6 bus: "can0"
  sdo { index: 0x1800 subindex: 1 type: "u32" value: "0x80000186" }
  sdo { index: 0x1800 subindex: 1 type: "u32" value: "0x185" } }
)");
  ASSERT_THAT(t.warnings, SizeIs(1));
  EXPECT_THAT(t.warnings[0].reason,
              HasSubstr("quad-6 TPDO1 (1800h) sends COB-ID 185h, as quad-5 TPDO1 (1800h) does on bus can0"));
}

// A generic node from the shipped DIO-16 EDS with 1005h/1006h added: a SYNC producer (CiA 301
// §7.5.2.5, §7.5.2.6) every `period_us`.
fs::path SyncProducerEds(std::uint32_t period_us) {
  std::ifstream in(kTopologies / "eds" / "canfleet-dio16.eds");
  std::stringstream text;
  text << in.rdbuf();
  std::string eds = text.str();
  const std::string list = "SupportedObjects=13\n";
  eds.replace(eds.find(list), list.size(), "SupportedObjects=15\n14=0x1005\n15=0x1006\n");
  eds +=
      "\n[1005]\nParameterName=COB-ID SYNC\nObjectType=0x7\nDataType=0x0007\nAccessType=rw\n"
      "DefaultValue=0x40000080\nPDOMapping=0\n"
      "\n[1006]\nParameterName=Communication cycle period\nObjectType=0x7\nDataType=0x0007\n"
      "AccessType=rw\nDefaultValue=" +
      std::to_string(period_us) + "\nPDOMapping=0\n";
  const fs::path file = fs::path(::testing::TempDir()) / "sync-producer.eds";
  std::ofstream(file) << eds;
  return file;
}

TEST(PdoWarningTest, ASyncDrivenTpdoIsWarnedOnlyOnABusWithoutSync) {
  const std::string sync_tpdo =
      kHead + R"(node { name: "quad-6" device: "quad-controller" node_id: 6 bus: "can0"
  sdo { index: 0x1800 subindex: 2 type: "u8" value: "2" } }
)";
  const LoadedTopology without = Load(sync_tpdo);
  ASSERT_THAT(without.warnings, SizeIs(1));
  EXPECT_EQ(without.warnings[0].field, "node[1].sdo[0].value");
  EXPECT_THAT(without.warnings[0].reason,
              AllOf(HasSubstr("quad-6 TPDO1 (1800h) is SYNC-driven (transmission type 2, sdo[0])"),
                    HasSubstr("no node produces SYNC on bus can0"), HasSubstr("never sent")));
  EXPECT_DOUBLE_EQ(without.loads[0].sync, 0.0);

  // With a SYNC every 10 ms: no warning; SYNC frames (DLC 0) count 100 times a second, and TPDO1
  // goes out at every 2nd SYNC.
  const LoadedTopology with = Load(sync_tpdo + R"(node { name: "sync" eds: ")" +
                                   SyncProducerEds(10000).string() + R"(" node_id: 20 bus: "can0" }
)");
  EXPECT_THAT(Messages(with), IsEmpty());
  EXPECT_GT(with.loads[0].sync, 0.0);
  EXPECT_THAT(with.loads[0].Describe(), HasSubstr("SYNC "));
  // quad-6's TPDO1, never sent without SYNC, now 50 8-byte frames of at most 135 bits a second;
  // and the DIO-16's own TPDO1 (1 byte, every 1000 ms: at most 65 bits).
  EXPECT_NEAR(with.loads[0].tpdos - without.loads[0].tpdos, (50.0 * 135 + 65) / 250000, 1e-9);
}

// ---- offered load (frame lengths: bus/physics/frame_timing.hpp MaxFrameBits) ---------------------

std::string Quads(int count, bool start_nodes) {
  std::string text = "name: \"fleet\"\n";
  if (!start_nodes) text += "orchestrator { start_nodes: false }\n";
  text += "bus { name: \"can0\" bitrate: 250000 }\n";
  for (int id = 1; id <= count; ++id)
    text += "node { name: \"quad-" + std::to_string(id) +
            "\" device: \"quad-controller\" node_id: " + std::to_string(id) +
            " bus: \"can0\" heartbeat { producer_ms: 500 } }\n";
  return text;
}

// 127 operational Quads on 250 kbit/s: each sends its four default TPDOs every 100 ms (AX020506
// §3.1.1: 8, 4, 2 and 8 bytes, at most 135 + 95 + 75 + 135 = 440 bits) and a heartbeat every
// 500 ms (1 byte, at most 65 bits): 127 × 4400 bit/s = 223.5 % and 127 × 130 bit/s = 6.6 %.
TEST(BusLoadTest, OneHundredTwentySevenQuadsOffer230PercentOf250kbits) {
  const LoadedTopology t = Load(Quads(127, true));
  ASSERT_THAT(t.loads, SizeIs(1));
  EXPECT_EQ(t.loads[0].bus, "can0");
  EXPECT_EQ(t.loads[0].bitrate, 250000u);
  EXPECT_NEAR(t.loads[0].tpdos, 127.0 * 440 * 10 / 250000, 1e-9);
  EXPECT_NEAR(t.loads[0].heartbeats, 127.0 * 65 * 2 / 250000, 1e-9);
  EXPECT_DOUBLE_EQ(t.loads[0].sync, 0.0);
  EXPECT_EQ(t.loads[0].Describe(), "230 % of 250 kbit/s (TPDOs 224 %, heartbeats 6.6 %)");
  ASSERT_THAT(t.warnings, SizeIs(1));
  EXPECT_EQ(t.warnings[0].Message(),
            kFile.string() +
                ":2:20: warning: bus[0].bitrate: bus can0: periodic traffic offers 230 % "
                "of 250 kbit/s (TPDOs 224 %, heartbeats 6.6 %): configuration SDOs and "
                "low-priority frames will starve");
}

TEST(BusLoadTest, TenQuadsFitAndNodesNeverStartedSendNoTpdos) {
  const LoadedTopology ten = Load(Quads(10, true));
  EXPECT_THAT(Messages(ten), IsEmpty());
  EXPECT_EQ(ten.loads[0].Describe(), "18 % of 250 kbit/s (TPDOs 18 %, heartbeats 0.5 %)");
  // Pre-operational nodes send no PDOs (CiA 301 §7.3.2.2 table 51), heartbeats still.
  const LoadedTopology idle = Load(Quads(127, false));
  EXPECT_THAT(Messages(idle), IsEmpty());
  EXPECT_DOUBLE_EQ(idle.loads[0].tpdos, 0.0);
  EXPECT_NEAR(idle.loads[0].heartbeats, 127.0 * 65 * 2 / 250000, 1e-9);
}

TEST(BusLoadTest, PercentText) {
  EXPECT_EQ(PercentText(0.0), "0 %");
  EXPECT_EQ(PercentText(0.048), "4.8 %");
  EXPECT_EQ(PercentText(2.3012), "230 %");
  BusLoad empty{.bus = "can1", .bitrate = 125000};
  EXPECT_EQ(empty.Describe(), "0 % of 125 kbit/s");
}

}  // namespace
}  // namespace canfleet::topology
