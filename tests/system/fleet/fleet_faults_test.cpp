// Issue 6, faults 1-3 end to end with Quad controllers (AX020506): a real orchestrator
// (`canfleet up`), real node processes, real sockets, driven through the real `canfleet` CLI.
// Each test checks what a CANopen master would see: the consumer's EMCY frame on the bus (the
// orchestrator's master port records it: status.last_emcy), its 1003h entry read by SDO, its NMT
// state after the 1029h reaction (from its heartbeat), its output in the manual's safe state, and
// the recovery after the fault clears.
//
// Manual references (../shared/seeds/quad-controller_AX020506.txt):
// - §4.1/§4.2: a lost heartbeat is EMCY 8130h, 1003h 0x08nn8130 (nn = the silent node);
// - §3.1 / CiA 301 §7.5.2.32 (1029h sub 1 default 0): a communication error takes an operational
//   node to pre-operational;
// - §4.2: in pre-operational, outputs under CAN control are off; 6340h = 1 (default) drives an
//   output to 7341h (0 mA) in the fault state.
// RPDO timeout and bus-off are not in the manual's EMCY list: the CiA 301 codes apply (8250h RPDO
// timeout, 8140h recovered from bus-off; see node/devices/quad_controller/quad_error_policy.hpp).
#include <gtest/gtest.h>

#include <chrono>

#include "tests/system/fleet/fleet_harness.hpp"

namespace canfleet::system_test {
namespace {

// quad-6 consumes quad-5's heartbeat and its TPDO1 (185h: 7100h.1 AI1) on RPDO1 (7330h.1, POUT1
// under CAN control, 3010h.1 = 0 default) with a 500 ms deadline.
constexpr const char* kTopology = R"(
name: "fleet-test"
bus { name: "can0" bitrate: 250000 }
node { name: "quad-5" device: "quad-controller" node_id: 5 bus: "can0"
       heartbeat { producer_ms: 200 } }
node { name: "quad-6" device: "quad-controller" node_id: 6 bus: "can0"
       heartbeat { producer_ms: 200 consumer { node: "quad-5" timeout_ms: 1000 } }
       sdo { index: 0x1400 subindex: 1 type: "u32" value: "0x80000206" }
       sdo { index: 0x1400 subindex: 1 type: "u32" value: "0x185" }
       sdo { index: 0x1400 subindex: 5 type: "u16" value: "500" } }
)";

constexpr auto kLong = std::chrono::seconds(30);

class FleetFaultsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(fleet.WaitReady()) << fleet.Log();
    ASSERT_TRUE(WaitUntil(
        [&] { return NmtOf("quad-6") == "operational" && NmtOf("quad-5") == "operational"; }, kLong))
        << fleet.Log();
    // CiA 301 §7.2.8.3.2.2: quad-6's consumer starts at the first heartbeat of quad-5 it receives
    // after 1016h was written. A heartbeat the orchestrator sees after quad-6 reported operational
    // (configured, then started) reached quad-6 too: wait for one.
    const auto since = std::chrono::steady_clock::now();
    ASSERT_TRUE(WaitUntil(
        [&] {
          const auto status = fleet.Status();
          const auto* producer = fleet.Node(status, "quad-5");
          const double elapsed_s =
              std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
          return producer->heartbeat_age_s() >= 0 && producer->heartbeat_age_s() < elapsed_s;
        },
        kLong));
  }

  std::string NmtOf(const std::string& node) const {
    const auto status = fleet.Status();
    const auto* n = fleet.Node(status, node);
    return n ? n->nmt_state() : "";
  }
  std::uint32_t LastEmcyOf(const std::string& node) const {
    const auto status = fleet.Status();
    const auto* n = fleet.Node(status, node);
    return n && n->has_last_emcy() ? n->last_emcy().code() : 0xFFFFFFFF;
  }
  /// POUT1 of quad-6 in mA, -1 when it cannot be read.
  double Pout1() const {
    const auto value = fleet.IoGet("quad-6", "OUT1.current_mA");
    return value ? std::stod(*value) : -1;
  }

  FleetUnderTest fleet{kTopology};
};

TEST_F(FleetFaultsTest, HeartbeatLossRaises8130hGoesPreOperationalAndRecovers) {
  const auto injected = fleet.Cli({"fault", "inject", "heartbeat-loss", "--node", "quad-5"});
  ASSERT_EQ(injected.exit_code, 0) << injected.err;

  EXPECT_TRUE(WaitUntil([&] { return LastEmcyOf("quad-6") == 0x8130; }, kLong)) << fleet.Log();
  EXPECT_TRUE(WaitUntil([&] { return NmtOf("quad-6") == "pre-operational"; }, kLong));
  std::string error;
  EXPECT_EQ(fleet.SdoReadUnsigned("quad-6", "0x1003", 1, "u32", &error), 0x08058130u) << error;
  EXPECT_EQ(fleet.SdoReadUnsigned("quad-6", "0x1001", 0, "u8", &error).value_or(0) & 0x01, 0x01u) << error;
  EXPECT_TRUE(WaitUntil([&] { return Pout1() == 0; }, kLong));

  const auto listed = fleet.Cli({"fault", "list", "--json"});
  EXPECT_NE(listed.out.find("HEARTBEAT_LOSS"), std::string::npos) << listed.out;

  ASSERT_EQ(fleet.Cli({"fault", "clear", "--all"}).exit_code, 0);
  // Heartbeats return: the consumer's error clears (error reset EMCY 0000h, 1001h = 0).
  EXPECT_TRUE(WaitUntil([&] { return LastEmcyOf("quad-6") == 0x0000; }, kLong));
  EXPECT_EQ(fleet.SdoReadUnsigned("quad-6", "0x1001", 0, "u8", &error), 0u) << error;
  // The master starts it again (CiA 301: a slave never leaves pre-operational by itself).
  ASSERT_EQ(fleet.Cli({"nmt", "start", "quad-6"}).exit_code, 0);
  EXPECT_TRUE(WaitUntil([&] { return NmtOf("quad-6") == "operational"; }, kLong));
}

TEST_F(FleetFaultsTest, RpdoTimeoutRaises8250hGoesPreOperationalAndRecovers) {
  const auto injected =
      fleet.Cli({"fault", "inject", "rpdo-timeout", "--node", "quad-6", "--cob-id", "0x185"});
  ASSERT_EQ(injected.exit_code, 0) << injected.err;

  EXPECT_TRUE(WaitUntil([&] { return LastEmcyOf("quad-6") == 0x8250; }, kLong)) << fleet.Log();
  EXPECT_TRUE(WaitUntil([&] { return NmtOf("quad-6") == "pre-operational"; }, kLong));
  std::string error;
  EXPECT_EQ(fleet.SdoReadUnsigned("quad-6", "0x1003", 1, "u32", &error).value_or(0) & 0xFFFF, 0x8250u)
      << error;
  EXPECT_TRUE(WaitUntil([&] { return Pout1() == 0; }, kLong));
  // quad-5 is untouched: only quad-6 misses 185h.
  EXPECT_EQ(NmtOf("quad-5"), "operational");

  ASSERT_EQ(fleet.Cli({"fault", "clear", "--all"}).exit_code, 0);
  ASSERT_EQ(fleet.Cli({"nmt", "start", "quad-6"}).exit_code, 0);
  EXPECT_TRUE(WaitUntil([&] { return NmtOf("quad-6") == "operational"; }, kLong));
  // PDOs flow again: the deadline error clears.
  EXPECT_TRUE(WaitUntil([&] { return LastEmcyOf("quad-6") == 0x0000; }, kLong));
}

TEST_F(FleetFaultsTest, BusOffSends8140hAfterRecoveryAndTheResetEmpties1003h) {
  const auto injected = fleet.Cli({"fault", "inject", "bus-off", "--node", "quad-6"});
  ASSERT_EQ(injected.exit_code, 0) << injected.err;

  // Automatic recovery after 128 x 11 recessive bits (5.6 ms at 250 kbit/s): the EMCY raised at
  // bus-off leaves after recovery, and the error is over: the reset removes 00008140h from 1003h
  // (AX020506 §3.1.4: "immediately removed when the error condition has been cleared"; sub 0 is
  // zero in an error-free state).
  EXPECT_TRUE(WaitUntil(
      [&] {
        const auto status = fleet.Status();
        const auto* n = fleet.Node(status, "quad-6");
        return n && n->emcy_count() >= 2 && n->controller() == "error-active";
      },
      kLong))
      << fleet.Log();
  EXPECT_TRUE(WaitUntil([&] { return NmtOf("quad-6") == "pre-operational"; }, kLong));
  std::string error;
  EXPECT_EQ(fleet.SdoReadUnsigned("quad-6", "0x1003", 0, "u8", &error), 0u) << error;
  EXPECT_TRUE(WaitUntil([&] { return Pout1() == 0; }, kLong));
  const auto log = fleet.Log();
  EXPECT_NE(log.find("quad-6: EMCY 8140h"), std::string::npos) << log;

  ASSERT_EQ(fleet.Cli({"nmt", "start", "quad-6"}).exit_code, 0);
  EXPECT_TRUE(WaitUntil([&] { return NmtOf("quad-6") == "operational"; }, kLong));
}

TEST_F(FleetFaultsTest, BusOffWithManualRecoveryHoldsUntilCleared) {
  const auto injected = fleet.Cli({"fault", "inject", "bus-off", "--node", "quad-6", "--manual-recovery"});
  ASSERT_EQ(injected.exit_code, 0) << injected.err;
  EXPECT_TRUE(WaitUntil(
      [&] {
        const auto status = fleet.Status();
        const auto* n = fleet.Node(status, "quad-6");
        return n && n->controller() == "bus-off" && n->tec() > 255;
      },
      kLong));
  // Its frames stop: no heartbeat reaches the master while it is bus-off.
  const auto before = fleet.Status();
  const double age = fleet.Node(before, "quad-6")->heartbeat_age_s();
  EXPECT_TRUE(WaitUntil(
      [&] {
        const auto status = fleet.Status();
        return fleet.Node(status, "quad-6")->heartbeat_age_s() > age + 1.0;
      },
      kLong));
  ASSERT_EQ(fleet.Cli({"fault", "clear", "--all"}).exit_code, 0);
  EXPECT_TRUE(WaitUntil(
      [&] {
        const auto status = fleet.Status();
        const auto* n = fleet.Node(status, "quad-6");
        return n && n->controller() == "error-active" && n->heartbeat_age_s() < 1.0;
      },
      kLong));
}

// Through the real CLI: an option bus-off does not take is refused by the orchestrator with what
// it takes (nothing is injected), a bad argument (exit 2); `--duration` holds the bus-off: the node's
// controller shows bus-off with TEC > 255 for the whole time while its recovery attempts fail (ISO
// 11898-1:2015 §12.1.4.2: 1408 bit times each, 5.6 ms at 250 kbit/s, counted as the fault's hits), then it
// recovers by itself.
TEST_F(FleetFaultsTest, BusOffHeldForADurationAndOptionsThatDoNotApplyAreRefused) {
  const auto refused = fleet.Cli({"fault", "inject", "bus-off", "--node", "quad-6", "--cob-id", "0x185"});
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_EQ(
      refused.err,
      "canfleet: --cob-id does not apply to bus-off (it takes --node, --bus, --duration, --manual-recovery, "
      "--label)\n");
  EXPECT_EQ(fleet.Node(fleet.Status(), "quad-6")->controller(), "error-active");
  // A kind without what it needs, an unknown node, an unknown signal: bad arguments too, each
  // with what would be valid (fault_kinds.cpp; the nearest names).
  const auto no_cob_id = fleet.Cli({"fault", "inject", "rpdo-timeout", "--node", "quad-6"});
  EXPECT_EQ(no_cob_id.exit_code, 2) << no_cob_id.err;
  EXPECT_NE(no_cob_id.err.find("--cob-id"), std::string::npos) << no_cob_id.err;
  const auto no_node = fleet.Cli({"io", "get", "quad-9"});
  EXPECT_EQ(no_node.exit_code, 2);
  EXPECT_EQ(
      no_node.err,
      "canfleet: no node called 'quad-9' in this fleet; nearest: quad-5, quad-6; all: canfleet status\n");
  const auto no_signal = fleet.Cli({"io", "get", "quad-5", "IN9.voltage_mV"});
  EXPECT_EQ(no_signal.exit_code, 2);
  EXPECT_EQ(no_signal.err,
            "canfleet: no signal IN9.voltage_mV on quad-5; nearest: IN1.voltage_mV, IN2.voltage_mV, "
            "IN3.voltage_mV; "
            "all: canfleet io get quad-5\n");

  const auto injected = fleet.Cli({"fault", "inject", "bus-off", "--node", "quad-6", "--duration", "2s"});
  ASSERT_EQ(injected.exit_code, 0) << injected.err;
  EXPECT_NE(
      injected.out.find("bus-off of quad-6 on can0, held for 2s (every recovery attempt fails until then)"),
      std::string::npos)
      << injected.out;
  // Its recovery attempts fail (the fault's hits count them) while it stays bus-off, counters shown.
  const auto start = std::chrono::steady_clock::now();
  control::Status held;
  ASSERT_TRUE(WaitUntil(
      [&] {
        held = fleet.Status();
        return held.faults_size() == 1 && held.faults(0).hits() > 10;
      },
      kLong))
      << fleet.Log();
  if (std::chrono::steady_clock::now() < start + std::chrono::milliseconds(1900)) {
    const auto* n = fleet.Node(held, "quad-6");
    EXPECT_EQ(n->controller(), "bus-off");
    EXPECT_GT(n->tec(), 255u);
  }
  EXPECT_TRUE(WaitUntil(
      [&] {
        const auto later = fleet.Status();
        const auto* n = fleet.Node(later, "quad-6");
        return n && n->controller() == "error-active" && later.faults_size() == 0;
      },
      kLong))
      << fleet.Log();
}

}  // namespace
}  // namespace canfleet::system_test
