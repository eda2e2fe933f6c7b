// Issue 16: the three faults the orchestrator injects, end to end on valve-12in12out (UMAX020411A)
// nodes under `canfleet up` with real processes; a Quad controller (quad-5) is the other party
// (heartbeat producer, TPDO1 185h = AIN1-4 in mV), the orchestrator the master.
//
// Manual references (../shared/seeds/valve-12in12out_UMAX020411A.txt):
// - §3.2.4 Table 33: 80nn8130h heartbeat timeout of node nn (EMCY 8130h), 00008100h RPDO timeout
//   (8100h), 00008140h bus-off (the EMCY column's 8400h is not a CiA code: 8140h, README-dictionary
//   and family_error_policy.hpp); §3.2.2: 1001h uses bit 0 only; the EMCY data bytes are channel,
//   description (the family's layout, family_error_policy.hpp).
// - §3.2.13 1029h sub 1 "Communication Fault", default 1 = no state change (valve-a); valve-b is
//   configured to 0 = pre-operational through the topology's SDO list.
// - §3.2.14: an RPDO not received within its event timer is a communication error; README choice 5:
//   the outputs driven by its objects take their fault reaction, 6340h = 1 (default) -> 7341h,
//   500 mA (§3.3.22, §3.3.29). Heartbeat loss and bus-off have only the 1029h reaction.
// - README choice 6: outputs keep running in pre-operational (stand-alone logic, §1.10, 5555h).
// - §3.4.34/§3.4.35: OUT1 is controlled by "CANopen message 1" (7300h.1, RPDO1 §3.2.14), scaled
//   300..1500 (7320h/7322h) onto 300..1500 mA (7321h/7323h): quad-5's AIN1 1000 mV -> 1000 mA.
#include <gtest/gtest.h>

#include "tests/system/fleet/product_fleet_test.hpp"

namespace canfleet::system_test {
namespace {

// Both valves consume quad-5's heartbeat (1016h) and its TPDO1 on RPDO1 (7300h.1-4, 8 bytes as
// TPDO1) with a 500 ms deadline (1400h.5; the manual's default 0 is no deadline).
constexpr const char* kTopology = R"(
name: "fleet-test"
bus { name: "can0" bitrate: 250000 }
node { name: "quad-5" device: "quad-controller" node_id: 5 bus: "can0"
       io { key: "IN1.voltage_mV" value: "1000" }
       heartbeat { producer_ms: 200 } }
node { name: "valve-a" device: "valve-12in12out" node_id: 32 bus: "can0"
       heartbeat { producer_ms: 200 consumer { node: "quad-5" timeout_ms: 1000 } }
       sdo { index: 0x1400 subindex: 1 type: "u32" value: "0x80000185" }
       sdo { index: 0x1400 subindex: 1 type: "u32" value: "0x185" }
       sdo { index: 0x1400 subindex: 5 type: "u16" value: "500" } }
node { name: "valve-b" device: "valve-12in12out" node_id: 33 bus: "can0"
       heartbeat { producer_ms: 200 consumer { node: "quad-5" timeout_ms: 1000 } }
       sdo { index: 0x1400 subindex: 1 type: "u32" value: "0x80000185" }
       sdo { index: 0x1400 subindex: 1 type: "u32" value: "0x185" }
       sdo { index: 0x1400 subindex: 5 type: "u16" value: "500" }
       sdo { index: 0x1029 subindex: 1 type: "u8" value: "0" } }
)";

constexpr const char* kOut1 = "OUT1.current_mA";

class FleetValveTest : public ProductFleetTest {
 protected:
  void SetUp() override {
    StartFleet(kTopology, {"quad-5", "valve-a", "valve-b"}, "quad-5");
    if (HasFatalFailure()) return;
    // OUT1 follows quad-5's AIN1 through RPDO1 (ramped at 2330h, 1000 ms for the full range).
    ASSERT_TRUE(WaitIo("valve-a", kOut1, 1000)) << IoText("valve-a", kOut1);
    ASSERT_TRUE(WaitIo("valve-b", kOut1, 1000)) << IoText("valve-b", kOut1);
  }
};

TEST_F(FleetValveTest, HeartbeatLossRaises80nn8130hAndReactsPer1029h) {
  ASSERT_TRUE(Cli({"fault", "inject", "heartbeat-loss", "--node", "quad-5"}));
  // Table 33: 80058130h, EMCY 8130h with channel 05h (the silent node), description 80h.
  for (const char* valve : {"valve-a", "valve-b"}) {
    ExpectErrorRecorded(valve, 0x8130, "05 80 00 00 00", 0x80058130u);
    EXPECT_TRUE(WaitUntil([&] { return LastEmcyOf(valve) == 0x8130u; }, kProductPatience)) << valve;
  }
  // §3.2.13: valve-b (1029h.1 = 0) goes pre-operational; valve-a (default 1) stays operational.
  EXPECT_TRUE(WaitNmt("valve-b", "pre-operational"));
  // No output reaction (choice 5): OUT1 holds its command, in pre-operational too (choice 6).
  EXPECT_TRUE(HoldsFor(
      [&] {
        return NmtOf("valve-a") == "operational" && Reads("valve-a", kOut1, 1000) &&
               Reads("valve-b", kOut1, 1000);
      },
      kNoChangeWindow, kNoChangeReason))
      << NmtOf("valve-a") << ", OUT1 " << IoText("valve-a", kOut1) << " / " << IoText("valve-b", kOut1);

  ASSERT_TRUE(Cli({"fault", "clear", "--all"}));
  // Heartbeats return: the error clears (EMCY 0000h, 1001h = 0, the entry leaves 1003h).
  for (const char* valve : {"valve-a", "valve-b"}) {
    EXPECT_TRUE(WaitUntil([&] { return LastEmcyOf(valve) == 0x0000u; }, kProductPatience)) << valve;
    EXPECT_EQ(Sdo(valve, "0x1001", 0, "u8"), 0u) << valve;
  }
  ASSERT_TRUE(Cli({"nmt", "start", "valve-b"}));
  EXPECT_TRUE(WaitNmt("valve-b", "operational"));
}

TEST_F(FleetValveTest, RpdoTimeoutRaises00008100hAndDrivesOutputsToTheirFaultValue) {
  ASSERT_TRUE(Cli({"fault", "inject", "rpdo-timeout", "--node", "valve-a", "--cob-id", "0x185"}));
  ASSERT_TRUE(Cli({"fault", "inject", "rpdo-timeout", "--node", "valve-b", "--cob-id", "0x185"}));
  for (const char* valve : {"valve-a", "valve-b"}) {
    ExpectErrorRecorded(valve, 0x8100, "00 00 00 00 00", 0x00008100u);
    // Choice 5, §3.3.22/§3.3.29: 6340h = 1 applies 7341h = 500 mA while the RPDO is timed out.
    EXPECT_TRUE(WaitIo(valve, kOut1, 500)) << valve << ": " << IoText(valve, kOut1);
  }
  EXPECT_TRUE(WaitNmt("valve-b", "pre-operational"));
  // valve-a keeps its state (1029h.1 = 1); quad-5 is untouched (only the valves miss 185h).
  EXPECT_TRUE(HoldsFor([&] { return NmtOf("valve-a") == "operational" && NmtOf("quad-5") == "operational"; },
                       kNoChangeWindow, kNoChangeReason));

  ASSERT_TRUE(Cli({"fault", "clear", "--all"}));
  // valve-a receives RPDO1 again: the timeout clears and OUT1 follows 7300h.1 again.
  EXPECT_TRUE(WaitUntil([&] { return LastEmcyOf("valve-a") == 0x0000u; }, kProductPatience));
  EXPECT_TRUE(WaitIo("valve-a", kOut1, 1000)) << IoText("valve-a", kOut1);
  // valve-b processes PDOs again once started (CiA 301: PDOs only in operational).
  ASSERT_TRUE(Cli({"nmt", "start", "valve-b"}));
  EXPECT_TRUE(WaitNmt("valve-b", "operational"));
  EXPECT_TRUE(WaitUntil([&] { return LastEmcyOf("valve-b") == 0x0000u; }, kProductPatience));
  EXPECT_TRUE(WaitIo("valve-b", kOut1, 1000)) << IoText("valve-b", kOut1);
}

TEST_F(FleetValveTest, BusOffSends8140hAfterRecoveryAndTheResetEmpties1003h) {
  for (const char* valve : {"valve-a", "valve-b"}) {
    const auto before = EmcyCountOf(valve);
    ASSERT_TRUE(Cli({"fault", "inject", "bus-off", "--node", valve}));
    // Automatic recovery (128 x 11 recessive bits); the 8140h "recovered from bus-off" leaves
    // then, followed by the error reset: the event is over.
    EXPECT_TRUE(WaitUntil(
        [&] {
          const auto status = fleet().Status();
          const auto* n = fleet().Node(status, valve);
          return n->emcy_count() >= before + 2 && n->controller() == "error-active";
        },
        kProductPatience))
        << fleet().Log();
    EXPECT_TRUE(WaitLog(EmcyLine(valve, 0x8140, 0x01, "00 00 00 00 00"))) << fleet().Log();
    // Table 33's 00008140h left 1003h with the reset (§3.2.4: "immediately removed when the error
    // condition has been cleared", sub-index 0 zero in an error-free state); 1001h is clear again.
    EXPECT_EQ(Sdo(valve, "0x1003", 0, "u8"), 0u) << valve;
    EXPECT_EQ(Sdo(valve, "0x1001", 0, "u8"), 0u) << valve;
  }
  // §3.2.13: 1029h.1 = 0 took valve-b to pre-operational at bus-off; valve-a (1) stayed.
  EXPECT_TRUE(WaitNmt("valve-b", "pre-operational"));
  // No output reaction (choice 5), and outputs run in pre-operational (choice 6).
  EXPECT_TRUE(HoldsFor(
      [&] {
        return NmtOf("valve-a") == "operational" && Reads("valve-a", kOut1, 1000) &&
               Reads("valve-b", kOut1, 1000);
      },
      kNoChangeWindow, kNoChangeReason));

  ASSERT_TRUE(Cli({"nmt", "start", "valve-b"}));
  EXPECT_TRUE(WaitNmt("valve-b", "operational"));
}

}  // namespace
}  // namespace canfleet::system_test
