// Issue 18: the data logger (datalogger-tc-analog, AX181001) as one process on two buses of
// `canfleet up`, with real node processes and the real `canfleet` CLI. can0 (250 kbit/s) carries
// its CAN1 port (node 10) and quad-5; can1 (125 kbit/s, the manual's factory rate) carries its
// CAN2 port (node 11) and quad-9. Each Quad consumes the data logger's heartbeat on its own bus and
// feeds the port with its TPDO1 (4 x 16 bit): quad-5's 185h into CAN1's RPDO1 (2500h.1-4), quad-9's
// 189h into CAN2's RPDO2 (2500h.5-8; §3.2.14 default mappings: the received values are shared
// objects, so the two ports fill different ones). The data logger consumes each Quad's heartbeat
// on the port whose bus carries it. The orchestrator is the master on both buses.
//
// Manual references (../shared/seeds/datalogger-tc-analog_UMAX181001.txt; the variant's README
// node/devices/datalogger_tc_analog/README.md for the policies where the manual is silent):
// - §3: "2 CAN interfaces which share manufacturer-specific objects but have separate
//   Communication Objects": each port has its own NMT state, heartbeat, EMCY, 1001h, 1003h, 1029h;
//   communication faults stay on the port where they happen (README "Two ports").
// - §3.2.4 Table 26: heartbeat of node nn lost 80nn8130h (EMCY 8130h), RPDO timeout 00008100h
//   (8100h), bus-off 00008140h (8140h, README B2); EMCY data: channel, then description; 1001h bit 0
//   (generic) only.
// - §3.2.13 1029h: sub 1 "Communication Fault", 0 = pre-operational, 1 = no state change (the
//   default). The topology sets CAN1's to 0 and leaves CAN2's at the default, so each test shows
//   both reactions. §3.2.14: an RPDO not received within its event timer is a network fault.
// - The data logger has no outputs (§1.1): the manual gives no output reaction. What it puts on
//   the network are its TPDOs (TPDO1-3 every 100 ms, §3.2.15); a port in pre-operational sends
//   none (CiA 301 §7.3.2.2.2), a port whose 1029h says "no state change" keeps sending them: both
//   are watched on the bus.
// - §3.4.22-3.4.26 (README "Factory thresholds"): the TC limits default to 0 and trip at room
//   temperature; the topology writes the demo configuration (2171h = 600.0 C, 2173h = 700.0 C) and
//   the test then clears each port's 1003h (§3.2.4: "cleared by writing a zero to sub-index 0").
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "tests/system/fleet/product_fleet_test.hpp"

namespace canfleet::system_test {
namespace {

constexpr const char* kTopology = R"(
name: "datalogger-test"
bus { name: "can0" bitrate: 250000 }
bus { name: "can1" bitrate: 125000 }
node { name: "quad-5" device: "quad-controller" node_id: 5 bus: "can0"
       heartbeat { producer_ms: 200 consumer { node: "datalogger" timeout_ms: 1000 } }
       sdo { index: 0x1029 subindex: 1 type: "u8" value: "1" } }
node { name: "quad-9" device: "quad-controller" node_id: 9 bus: "can1"
       heartbeat { producer_ms: 200 consumer { node: "datalogger" timeout_ms: 1000 } }
       sdo { index: 0x1029 subindex: 1 type: "u8" value: "1" } }
node { name: "datalogger" device: "datalogger-tc-analog" bus: "can0" bus: "can1" node_id: 10 node_id: 11
       heartbeat { producer_ms: 200
                   consumer { node: "quad-5" timeout_ms: 1000 }
                   consumer { node: "quad-9" timeout_ms: 1000 } }
       sdo { index: 0x2171 subindex: 1 type: "i16" value: "6000" }
       sdo { index: 0x2171 subindex: 2 type: "i16" value: "6000" }
       sdo { index: 0x2171 subindex: 3 type: "i16" value: "6000" }
       sdo { index: 0x2171 subindex: 4 type: "i16" value: "6000" }
       sdo { index: 0x2173 subindex: 1 type: "i16" value: "7000" }
       sdo { index: 0x2173 subindex: 2 type: "i16" value: "7000" }
       sdo { index: 0x2173 subindex: 3 type: "i16" value: "7000" }
       sdo { index: 0x2173 subindex: 4 type: "i16" value: "7000" }
       sdo { index: 0x1400 subindex: 1 type: "u32" value: "0x80000185" }
       sdo { index: 0x1400 subindex: 1 type: "u32" value: "0x185" }
       sdo { index: 0x1400 subindex: 5 type: "u16" value: "500" }
       sdo { index: 0x1029 subindex: 1 type: "u8" value: "0" }
       sdo { port: 1 index: 0x1401 subindex: 1 type: "u32" value: "0x189" }
       sdo { port: 1 index: 0x1401 subindex: 5 type: "u16" value: "500" } }
)";

constexpr const char* kLogger = "datalogger";
constexpr int kCan1 = 0;  // port index (canfleet's --port is 0-based)
constexpr int kCan2 = 1;
constexpr const char* kBus[] = {"can0", "can1"};

class DataLoggerFleetTest : public ProductFleetTest {
 protected:
  void SetUp() override {
    StartFleet(kTopology, {"quad-5", "quad-9", kLogger}, "quad-5");
    if (HasFatalFailure()) return;
    ASSERT_TRUE(WaitPortNmt(kCan2, "operational")) << fleet().Log();
    // The data logger's CAN2 consumer starts with quad-9's first heartbeat after 1016h was
    // written (CiA 301 §7.2.8.3.2.2): wait for one seen after CAN2 reported operational.
    const auto since = std::chrono::steady_clock::now();
    ASSERT_TRUE(WaitUntil(
        [&] {
          const auto status = fleet().Status();
          const double age = fleet().Node(status, "quad-9")->heartbeat_age_s();
          return age >= 0 &&
                 age < std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
        },
        kProductPatience));
    // The demo thresholds took effect (no TC fault left); each port's history starts empty (the
    // first conversion may have tripped the factory limits before the writes arrived).
    for (const int port : {kCan1, kCan2}) {
      ASSERT_TRUE(WaitUntil([&] { return SdoOn(port, "0x1001", 0, "u8") == 0u; }, kProductPatience))
          << "port " << port + 1 << "\n"
          << fleet().Log();
      ASSERT_TRUE(
          Cli({"sdo", "write", kLogger, "0x1003", "0", "u8", "0", "--port", std::to_string(port + 1)}));
      ASSERT_EQ(SdoOn(port, "0x1003", 0, "u8"), 0u) << "port " << port + 1;
    }
  }

  /// What the master sees of the data logger's port `port` (`canfleet status`, one row per port).
  control::PortStatus PortStatusOf(int port) {
    const auto status = fleet().Status();
    const auto* node = fleet().Node(status, kLogger);
    return port < node->ports_size() ? node->ports(port) : control::PortStatus();
  }
  std::string PortNmt(int port) { return PortStatusOf(port).nmt_state(); }
  bool WaitPortNmt(int port, const std::string& state) {
    return WaitUntil([&] { return PortNmt(port) == state; }, kProductPatience);
  }
  std::uint64_t PortEmcyCount(int port) { return PortStatusOf(port).emcy_count(); }
  std::optional<std::uint32_t> PortLastEmcy(int port) {
    const auto p = PortStatusOf(port);
    if (!p.has_last_emcy()) return std::nullopt;
    return p.last_emcy().code();
  }

  /// `canfleet sdo read datalogger INDEX SUB TYPE --port PORT`: the raw value (little-endian), or
  /// nullopt when it aborted or did not answer.
  std::optional<std::uint64_t> SdoOn(int port, const std::string& index, int sub, const std::string& type) {
    const auto result = fleet().Cli({"sdo", "read", kLogger, index, std::to_string(sub), type, "--port",
                                     std::to_string(port + 1), "--json"});
    if (result.exit_code != 0) return std::nullopt;
    control::SdoData data;
    if (!ParseJson(result.out, data)) return std::nullopt;
    std::uint64_t value = 0;
    for (std::size_t i = data.data().size(); i-- > 0;)
      value = (value << 8) | static_cast<std::uint8_t>(data.data()[i]);
    return value;
  }

  /// The orchestrator's EMCY line for the data logger's port on `bus` (fleet.cpp names the bus of
  /// a node with several ports).
  static std::string LoggerEmcy(std::uint16_t code, std::uint8_t reg, const std::string& data, int port) {
    return EmcyLine(kLogger, code, reg, data) + " (" + kBus[port] + ")";
  }

  /// Watches `bus` with `canfleet dump` until `heartbeats` heartbeats 700h+`node_id` carrying
  /// `state` and `tpdos` TPDO1 frames 180h+`node_id` have passed (or the patience runs out).
  bool SeeTraffic(const std::string& bus, int node_id, const std::string& state, int heartbeats, int tpdos) {
    const int seen = CountTpdos(bus, node_id, state, heartbeats, tpdos);
    EXPECT_GE(seen, tpdos) << bus << ": TPDO1 of node " << node_id;
    return seen >= tpdos;
  }

  /// The port sends no TPDO (CiA 301 §7.3.2.2.2: no PDO outside operational): watched for five of
  /// its heartbeats carrying `state` (one second at 200 ms, ten periods of its 100 ms TPDO1).
  void ExpectNoTpdos(const std::string& bus, int node_id, const std::string& state) {
    EXPECT_EQ(CountTpdos(bus, node_id, state, 5, 0), 0) << bus << ": TPDO1 of node " << node_id;
  }

  /// TPDO1 frames 180h+`node_id` seen on `bus` (`canfleet dump`) until `heartbeats` heartbeats
  /// 700h+`node_id` carrying `state` and at least `tpdos` TPDOs have passed (or the patience runs
  /// out, a test failure).
  int CountTpdos(const std::string& bus, int node_id, const std::string& state, int heartbeats, int tpdos) {
    char heartbeat[32], tpdo[32];
    std::snprintf(heartbeat, sizeof heartbeat, " %s %03X#%s", bus.c_str(), 0x700 + node_id, state.c_str());
    std::snprintf(tpdo, sizeof tpdo, " %s %03X#", bus.c_str(), 0x180 + node_id);
    ChildProcess dump({PROGRAM_CANFLEET, "--control", fleet().control(), "dump", bus},
                      fleet().dir().File("dump-" + bus + ".log"));
    int seen_heartbeats = 0, seen_tpdos = 0;
    const auto done = dump.WaitForLine(
        [&](const std::string& line) {
          if (line.find(heartbeat) != std::string::npos) ++seen_heartbeats;
          if (line.find(tpdo) != std::string::npos) ++seen_tpdos;
          return seen_heartbeats >= heartbeats && seen_tpdos >= tpdos;
        },
        kProductPatience);
    EXPECT_TRUE(done.has_value()) << bus << ": " << seen_heartbeats << " heartbeats" << heartbeat << ", "
                                  << seen_tpdos << " TPDOs" << tpdo;
    return seen_tpdos;
  }
};

// §3.2.4 Table 26 (80nn8130h), §3.2.13 (1029h sub 1): a lost heartbeat is reported by the port
// that consumed it, with that port's 1029h reaction; the other port sees nothing.
TEST_F(DataLoggerFleetTest, HeartbeatLossIsReportedByTheConsumingPortWithItsOwnReaction) {
  ASSERT_TRUE(Cli({"fault", "inject", "heartbeat-loss", "--node", "quad-5"}));
  EXPECT_TRUE(WaitLog(LoggerEmcy(0x8130, 0x01, "05 80 00 00 00", kCan1))) << fleet().Log();
  EXPECT_EQ(SdoOn(kCan1, "0x1003", 0, "u8"), 1u);
  EXPECT_EQ(SdoOn(kCan1, "0x1003", 1, "u32"), 0x80058130u);
  EXPECT_EQ(SdoOn(kCan1, "0x1001", 0, "u8"), 0x01u);
  EXPECT_TRUE(WaitPortNmt(kCan1, "pre-operational"));  // CAN1's 1029h.1 = 0
  ExpectNoTpdos("can0", 10, "7F");
  // CAN2 is untouched: no entry, no error, still operational.
  EXPECT_EQ(SdoOn(kCan2, "0x1003", 0, "u8"), 0u);
  EXPECT_EQ(SdoOn(kCan2, "0x1001", 0, "u8"), 0u);
  EXPECT_EQ(PortNmt(kCan2), "operational");

  // CAN2 loses quad-9: 80098130h there; 1029h.1 = 1 (the manual's default): no state change, so
  // its TPDOs keep coming.
  ASSERT_TRUE(Cli({"fault", "inject", "heartbeat-loss", "--node", "quad-9"}));
  EXPECT_TRUE(WaitLog(LoggerEmcy(0x8130, 0x01, "09 80 00 00 00", kCan2))) << fleet().Log();
  EXPECT_EQ(SdoOn(kCan2, "0x1003", 1, "u32"), 0x80098130u);
  EXPECT_EQ(SdoOn(kCan2, "0x1001", 0, "u8"), 0x01u);
  EXPECT_EQ(PortNmt(kCan2), "operational");
  SeeTraffic("can1", 11, "05", 2, 3);
  EXPECT_EQ(SdoOn(kCan1, "0x1003", 0, "u8"), 1u);  // CAN1 gained nothing from CAN2's fault

  // Heartbeats return: each port resets its error (EMCY 0000h, 1001h = 0); the master starts CAN1.
  ASSERT_TRUE(Cli({"fault", "clear", "--all"}));
  for (const int port : {kCan1, kCan2}) {
    EXPECT_TRUE(WaitUntil([&] { return PortLastEmcy(port) == 0x0000u; }, kProductPatience)) << port;
    EXPECT_EQ(SdoOn(port, "0x1001", 0, "u8"), 0u) << port;
  }
  ASSERT_TRUE(Cli({"nmt", "start", kLogger}));
  EXPECT_TRUE(WaitPortNmt(kCan1, "operational"));
}

// §3.2.14, §3.2.4 Table 26 (00008100h), §3.2.13: an RPDO with an event timer (500 ms) misses its
// frames on one port only (CAN1's RPDO1 185h, then CAN2's RPDO2 189h).
TEST_F(DataLoggerFleetTest, RpdoTimeoutIsReportedByThePortThatMissesItsRpdo) {
  ASSERT_TRUE(
      Cli({"fault", "inject", "rpdo-timeout", "--node", kLogger, "--bus", "can0", "--cob-id", "0x185"}));
  EXPECT_TRUE(WaitLog(LoggerEmcy(0x8100, 0x01, "00 00 00 00 00", kCan1))) << fleet().Log();
  EXPECT_EQ(SdoOn(kCan1, "0x1003", 1, "u32"), 0x00008100u);
  EXPECT_EQ(SdoOn(kCan1, "0x1001", 0, "u8"), 0x01u);
  EXPECT_TRUE(WaitPortNmt(kCan1, "pre-operational"));
  ExpectNoTpdos("can0", 10, "7F");
  EXPECT_EQ(SdoOn(kCan2, "0x1003", 0, "u8"), 0u);
  EXPECT_EQ(PortNmt(kCan2), "operational");
  EXPECT_EQ(NmtOf("quad-5"), "operational");  // only the data logger misses 185h

  ASSERT_TRUE(
      Cli({"fault", "inject", "rpdo-timeout", "--node", kLogger, "--bus", "can1", "--cob-id", "0x189"}));
  EXPECT_TRUE(WaitLog(LoggerEmcy(0x8100, 0x01, "00 00 00 00 00", kCan2))) << fleet().Log();
  EXPECT_EQ(SdoOn(kCan2, "0x1003", 1, "u32"), 0x00008100u);
  EXPECT_EQ(SdoOn(kCan2, "0x1001", 0, "u8"), 0x01u);
  EXPECT_EQ(PortNmt(kCan2), "operational");  // 1029h.1 = 1: no state change
  SeeTraffic("can1", 11, "05", 2, 3);

  // The frames flow again: the errors reset once an RPDO arrives in operational.
  ASSERT_TRUE(Cli({"fault", "clear", "--all"}));
  ASSERT_TRUE(Cli({"nmt", "start", kLogger}));
  EXPECT_TRUE(WaitPortNmt(kCan1, "operational"));
  for (const int port : {kCan1, kCan2}) {
    EXPECT_TRUE(WaitUntil([&] { return PortLastEmcy(port) == 0x0000u; }, kProductPatience)) << port;
    EXPECT_EQ(SdoOn(port, "0x1001", 0, "u8"), 0u) << port;
  }
}

// §3.2.4 Table 26 (00008140h "Bus OFF Event", EMCY 8140h: README B2): after an automatic recovery
// the port sends 8140h, then the error reset that removes the entry (§3.2.4: "immediately removed
// when the error condition has been cleared"), and reacts per its own 1029h sub 1 (README B5).
TEST_F(DataLoggerFleetTest, BusOffIsReportedAfterRecoveryByThatPortOnly) {
  const auto before = PortEmcyCount(kCan2);
  ASSERT_TRUE(Cli({"fault", "inject", "bus-off", "--node", kLogger, "--bus", "can1"}));
  EXPECT_TRUE(WaitUntil(
      [&] {
        const auto p = PortStatusOf(kCan2);
        return p.emcy_count() >= before + 2 && p.controller() == "error-active";
      },
      kProductPatience))
      << fleet().Log();
  EXPECT_TRUE(WaitLog(LoggerEmcy(0x8140, 0x01, "00 00 00 00 00", kCan2))) << fleet().Log();
  EXPECT_EQ(SdoOn(kCan2, "0x1003", 0, "u8"), 0u);  // error-free again: sub-index 0 is zero
  EXPECT_EQ(SdoOn(kCan2, "0x1001", 0, "u8"), 0u);
  EXPECT_EQ(PortNmt(kCan2), "operational");  // 1029h.1 = 1
  EXPECT_EQ(SdoOn(kCan1, "0x1003", 0, "u8"), 0u);
  EXPECT_EQ(PortNmt(kCan1), "operational");

  ASSERT_TRUE(Cli({"fault", "inject", "bus-off", "--node", kLogger, "--bus", "can0"}));
  EXPECT_TRUE(WaitLog(LoggerEmcy(0x8140, 0x01, "00 00 00 00 00", kCan1))) << fleet().Log();
  EXPECT_TRUE(WaitPortNmt(kCan1, "pre-operational"));  // 1029h.1 = 0
  ExpectNoTpdos("can0", 10, "7F");
  EXPECT_TRUE(WaitUntil([&] { return PortLastEmcy(kCan1) == 0x0000u; }, kProductPatience));
  EXPECT_EQ(SdoOn(kCan1, "0x1003", 0, "u8"), 0u);
  EXPECT_EQ(SdoOn(kCan2, "0x1003", 0, "u8"), 0u);
  EXPECT_EQ(PortNmt(kCan2), "operational");

  ASSERT_TRUE(Cli({"nmt", "start", kLogger}));
  EXPECT_TRUE(WaitPortNmt(kCan1, "operational"));
}

// Issue 18 / README "Two ports": one port's bus-off does not silence the other. CAN1 is held
// bus-off; meanwhile CAN2's heartbeats (operational) and TPDO1 keep arriving on can1, its consumer
// quad-9 misses nothing, and CAN2's NMT state and controller do not change.
TEST_F(DataLoggerFleetTest, BusOffOfOnePortLeavesTheOtherPortsTrafficUnaffected) {
  const auto quad9_emcys = EmcyCountOf("quad-9");
  const auto can2_emcys = PortEmcyCount(kCan2);
  ASSERT_TRUE(Cli({"fault", "inject", "bus-off", "--node", kLogger, "--bus", "can0", "--manual-recovery"}));
  ASSERT_TRUE(WaitUntil([&] { return PortStatusOf(kCan1).controller() == "bus-off"; }, kProductPatience))
      << fleet().Log();

  EXPECT_TRUE(SeeTraffic("can1", 11, "05", 5, 10));
  // quad-5 consumes CAN1's heartbeat (1000 ms) and notices the silent port: 8130h in the Quad's
  // own layout (AX020506 §4.1: channel 0Ah = node 10, description 08h).
  EXPECT_TRUE(WaitLog(EmcyLine("quad-5", 0x8130, 0x01, "0A 08 00 00 00"))) << fleet().Log();
  // Everything above happened while CAN1 was still bus-off.
  const auto can1 = PortStatusOf(kCan1);
  EXPECT_EQ(can1.controller(), "bus-off");
  EXPECT_GT(can1.tec(), 255u);
  const auto can2 = PortStatusOf(kCan2);
  EXPECT_EQ(can2.nmt_state(), "operational");
  EXPECT_EQ(can2.controller(), "error-active");
  EXPECT_GE(can2.heartbeat_age_s(), 0);
  EXPECT_LT(can2.heartbeat_age_s(), 2.0);  // ten periods of 200 ms
  EXPECT_EQ(can2.emcy_count(), can2_emcys);
  EXPECT_EQ(EmcyCountOf("quad-9"), quad9_emcys);  // never missed CAN2's heartbeat
  EXPECT_EQ(NmtOf("quad-9"), "operational");

  ASSERT_TRUE(Cli({"fault", "clear", "--all"}));
  EXPECT_TRUE(WaitUntil(
      [&] {
        const auto p = PortStatusOf(kCan1);
        return p.controller() == "error-active" && p.heartbeat_age_s() >= 0 && p.heartbeat_age_s() < 2.0;
      },
      kProductPatience))
      << fleet().Log();
  EXPECT_EQ(PortStatusOf(kCan2).emcy_count(), can2_emcys);
}

// §1.2, §3.4.23 (2171h), §3.2.4 Table 26 (0210F011h): the main behaviour. TC1 crosses its high
// warning (600.0 C); the fault is the device's, so both ports report it (README "Two ports");
// 1029h sub 3 is 1 (no state change) on both.
TEST_F(DataLoggerFleetTest, ThermocoupleOverItsWarningThresholdIsReportedOnBothPorts) {
  // The log may already hold an F011h line from SetUp (the first conversion against the factory
  // limits): the new EMCY is the one counted after the input changed.
  const std::uint64_t emcys_before[] = {PortEmcyCount(kCan1), PortEmcyCount(kCan2)};
  ASSERT_TRUE(Cli({"io", "set", kLogger, "TC1.temperature_C", "650"}));
  for (const int port : {kCan1, kCan2}) {
    EXPECT_TRUE(
        WaitUntil([&] { return PortEmcyCount(port) > emcys_before[port] && PortLastEmcy(port) == 0xF011u; },
                  kProductPatience))
        << port << "\n"
        << fleet().Log();
    EXPECT_TRUE(WaitLog(LoggerEmcy(0xF011, 0x01, "10 02 00 00 00", port))) << fleet().Log();
    EXPECT_EQ(SdoOn(port, "0x1003", 1, "u32"), 0x0210F011u) << port;
    EXPECT_EQ(SdoOn(port, "0x1001", 0, "u8"), 0x01u) << port;
    EXPECT_EQ(PortNmt(port), "operational") << port;
  }
  // 6100h.1 (0.1 C) is one shared object, read on either port.
  const auto can1 = SdoOn(kCan1, "0x6100", 1, "i16");
  EXPECT_TRUE(can1 && *can1 >= 6495 && *can1 <= 6505) << can1.value_or(0);
  EXPECT_EQ(SdoOn(kCan2, "0x6100", 1, "i16"), can1);

  ASSERT_TRUE(Cli({"io", "set", kLogger, "TC1.temperature_C", "25"}));
  for (const int port : {kCan1, kCan2}) {
    EXPECT_TRUE(WaitUntil([&] { return PortLastEmcy(port) == 0x0000u; }, kProductPatience)) << port;
    EXPECT_EQ(SdoOn(port, "0x1001", 0, "u8"), 0u) << port;
  }
}

// §3.2.7: "The 'save' action on either CAN buses will apply to the parameters on both buses".
// A shared object (2170h.1, TC1 low warning) and a communication object of CAN1 (1801h.5, TPDO2's
// event timer) are written, CAN2 saves (1010h.1 "save"), the power is cycled: both are kept, and
// the shared value reads the same on either port.
TEST_F(DataLoggerFleetTest, SaveOnTheSecondPortAndPowerCycleKeepTheSharedValues) {
  ASSERT_TRUE(Cli({"sdo", "write", kLogger, "0x2170", "1", "i16", "-400"}));
  ASSERT_TRUE(Cli({"sdo", "write", kLogger, "0x1801", "5", "u16", "250"}));
  ASSERT_TRUE(Cli({"sdo", "write", kLogger, "0x1010", "1", "u32", "0x65766173", "--port", "CAN2"}));
  const auto before = fleet().Status();
  const int old_pid = fleet().Node(before, kLogger)->pid();
  ASSERT_GT(old_pid, 0);

  ASSERT_TRUE(Cli({"fault", "inject", "power-cycle", "--node", kLogger}));
  EXPECT_TRUE(WaitUntil(
      [&] {
        const auto status = fleet().Status();
        const auto* n = fleet().Node(status, kLogger);
        return n->pid() > 0 && n->pid() != old_pid && n->ports_size() == 2 && n->ports(0).booted() &&
               n->ports(1).booted() && n->ports(0).nmt_state() == "operational" &&
               n->ports(1).nmt_state() == "operational";
      },
      kProductPatience))
      << fleet().Log();
  EXPECT_EQ(SdoOn(kCan1, "0x2170", 1, "i16"), 0xFE70u);  // -400 = -40.0 C
  EXPECT_EQ(SdoOn(kCan2, "0x2170", 1, "i16"), 0xFE70u);
  EXPECT_EQ(SdoOn(kCan1, "0x1801", 5, "u16"), 250u);
  EXPECT_EQ(SdoOn(kCan2, "0x1801", 5, "u16"), 100u);  // CAN2's own TPDO2 kept its default
}

}  // namespace
}  // namespace canfleet::system_test
