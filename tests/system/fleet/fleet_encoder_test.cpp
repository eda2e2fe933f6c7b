// Issue 17: the three faults the orchestrator injects, end to end on encoder-dual-valve (AX023241)
// nodes under `canfleet up` with real processes; a Quad controller (quad-5) is the other party
// (heartbeat producer; TPDO1 185h cut to AIN1-2 in mV, 4 bytes, the length of the encoder's
// RPDO1), the orchestrator the master.
//
// Manual references (../shared/seeds/encoder-dual-valve_AX023241.txt; the README's "EMCY codes"
// table: this manual lists none, the family's are used):
// - heartbeat of node nn lost: EMCY 8130h, 1003h 80nn8130h (C3-1.2.4); RPDO timeout 8100h,
//   00008100h; bus-off 8140h, 00008140h removed at the error reset; 1001h bit 0 only
//   (C3-1.2.2); EMCY data bytes channel, description (family_error_policy.hpp).
// - C3-1.2.11 1029h sub 1 "Communication Error", default 1 = no state change (encoder-a);
//   encoder-b is configured to 0 = pre-operational through the topology's SDO list.
// - 1.4 Table 12, C3-1.3.24: an RPDO timeout puts the values it maps in error; an output they
//   control takes its Control Fault Response 6340h, default 0 = shut off (README "EMCY codes").
// - README choice 7 (Quad §4.2): outputs under CAN control are off outside operational.
// - 1.3 Tables 6/7, C3-1.4.15/16: OUT1 is controlled by received CAN message 1 (7300h.1, RPDO1
//   C3-1.2.16), 7320h..7322h (0..5000) onto 7321h..7323h (0..5000 mA): AIN1 1000 mV -> 1000 mA.
#include <gtest/gtest.h>

#include "tests/system/fleet/product_fleet_test.hpp"

namespace canfleet::system_test {
namespace {

// quad-5's TPDO1 carries AIN1-2 only (1A00h.0 = 2, written while the PDO is invalid, CiA 301
// §7.2.2.4): an 8-byte TPDO would be a "PDO length exceeded" error (CiA 301 8220h) on the
// encoder's 4-byte RPDO1.
constexpr const char* kTopology = R"(
name: "fleet-test"
bus { name: "can0" bitrate: 250000 }
node { name: "quad-5" device: "quad-controller" node_id: 5 bus: "can0"
       io { key: "IN1.voltage_mV" value: "1000" }
       io { key: "IN2.voltage_mV" value: "800" }
       sdo { index: 0x1800 subindex: 1 type: "u32" value: "0x80000185" }
       sdo { index: 0x1A00 subindex: 0 type: "u8" value: "2" }
       sdo { index: 0x1800 subindex: 1 type: "u32" value: "0x185" }
       heartbeat { producer_ms: 200 } }
node { name: "encoder-a" device: "encoder-dual-valve" node_id: 40 bus: "can0"
       heartbeat { producer_ms: 200 consumer { node: "quad-5" timeout_ms: 1000 } }
       sdo { index: 0x1400 subindex: 1 type: "u32" value: "0x80000185" }
       sdo { index: 0x1400 subindex: 1 type: "u32" value: "0x185" }
       sdo { index: 0x1400 subindex: 5 type: "u16" value: "500" } }
node { name: "encoder-b" device: "encoder-dual-valve" node_id: 41 bus: "can0"
       heartbeat { producer_ms: 200 consumer { node: "quad-5" timeout_ms: 1000 } }
       sdo { index: 0x1400 subindex: 1 type: "u32" value: "0x80000185" }
       sdo { index: 0x1400 subindex: 1 type: "u32" value: "0x185" }
       sdo { index: 0x1400 subindex: 5 type: "u16" value: "500" }
       sdo { index: 0x1029 subindex: 1 type: "u8" value: "0" } }
)";

constexpr const char* kOut1 = "OUT1.current_mA";

class FleetEncoderTest : public ProductFleetTest {
 protected:
  void SetUp() override {
    StartFleet(kTopology, {"quad-5", "encoder-a", "encoder-b"}, "quad-5");
    if (HasFatalFailure()) return;
    // OUT1 follows quad-5's AIN1 through RPDO1 (ramped, 2330h).
    ASSERT_TRUE(WaitIo("encoder-a", kOut1, 1000)) << IoText("encoder-a", kOut1);
    ASSERT_TRUE(WaitIo("encoder-b", kOut1, 1000)) << IoText("encoder-b", kOut1);
  }
};

TEST_F(FleetEncoderTest, HeartbeatLossRaises80nn8130hAndReactsPer1029h) {
  ASSERT_TRUE(Cli({"fault", "inject", "heartbeat-loss", "--node", "quad-5"}));
  for (const char* encoder : {"encoder-a", "encoder-b"}) {
    ExpectErrorRecorded(encoder, 0x8130, "05 80 00 00 00", 0x80058130u);
    EXPECT_TRUE(WaitUntil([&] { return LastEmcyOf(encoder) == 0x8130u; }, kProductPatience)) << encoder;
  }
  // C3-1.2.11: encoder-b (1029h.1 = 0) pre-operational, where its CAN-controlled OUT1 is off
  // (choice 7); encoder-a (default 1) stays operational and keeps driving OUT1.
  EXPECT_TRUE(WaitNmt("encoder-b", "pre-operational"));
  EXPECT_TRUE(WaitIo("encoder-b", kOut1, 0)) << IoText("encoder-b", kOut1);
  EXPECT_TRUE(HoldsFor([&] { return NmtOf("encoder-a") == "operational" && Reads("encoder-a", kOut1, 1000); },
                       kNoChangeWindow, kNoChangeReason))
      << NmtOf("encoder-a") << ", OUT1 " << IoText("encoder-a", kOut1);

  ASSERT_TRUE(Cli({"fault", "clear", "--all"}));
  for (const char* encoder : {"encoder-a", "encoder-b"}) {
    EXPECT_TRUE(WaitUntil([&] { return LastEmcyOf(encoder) == 0x0000u; }, kProductPatience)) << encoder;
    EXPECT_EQ(Sdo(encoder, "0x1001", 0, "u8"), 0u) << encoder;
  }
  ASSERT_TRUE(Cli({"nmt", "start", "encoder-b"}));
  EXPECT_TRUE(WaitNmt("encoder-b", "operational"));
  EXPECT_TRUE(WaitIo("encoder-b", kOut1, 1000)) << IoText("encoder-b", kOut1);
}

TEST_F(FleetEncoderTest, RpdoTimeoutRaises00008100hAndShutsTheControlledOutputOff) {
  ASSERT_TRUE(Cli({"fault", "inject", "rpdo-timeout", "--node", "encoder-a", "--cob-id", "0x185"}));
  ASSERT_TRUE(Cli({"fault", "inject", "rpdo-timeout", "--node", "encoder-b", "--cob-id", "0x185"}));
  for (const char* encoder : {"encoder-a", "encoder-b"}) {
    ExpectErrorRecorded(encoder, 0x8100, "00 00 00 00 00", 0x00008100u);
    // Table 12: 6340h = 0 (default) shuts OUT1 off while 7300h.1 is in error.
    EXPECT_TRUE(WaitIo(encoder, kOut1, 0)) << encoder << ": " << IoText(encoder, kOut1);
  }
  EXPECT_TRUE(WaitNmt("encoder-b", "pre-operational"));
  // encoder-a keeps its state (1029h.1 = 1); quad-5 is untouched (only the encoders miss 185h).
  EXPECT_TRUE(
      HoldsFor([&] { return NmtOf("encoder-a") == "operational" && NmtOf("quad-5") == "operational"; },
               kNoChangeWindow, kNoChangeReason));

  ASSERT_TRUE(Cli({"fault", "clear", "--all"}));
  EXPECT_TRUE(WaitUntil([&] { return LastEmcyOf("encoder-a") == 0x0000u; }, kProductPatience));
  EXPECT_TRUE(WaitIo("encoder-a", kOut1, 1000)) << IoText("encoder-a", kOut1);
  ASSERT_TRUE(Cli({"nmt", "start", "encoder-b"}));
  EXPECT_TRUE(WaitNmt("encoder-b", "operational"));
  EXPECT_TRUE(WaitUntil([&] { return LastEmcyOf("encoder-b") == 0x0000u; }, kProductPatience));
  EXPECT_TRUE(WaitIo("encoder-b", kOut1, 1000)) << IoText("encoder-b", kOut1);
}

TEST_F(FleetEncoderTest, BusOffSends8140hAfterRecoveryAndTheResetEmpties1003h) {
  for (const char* encoder : {"encoder-a", "encoder-b"}) {
    const auto before = EmcyCountOf(encoder);
    ASSERT_TRUE(Cli({"fault", "inject", "bus-off", "--node", encoder}));
    // Automatic recovery; the 8140h "recovered from bus-off" leaves then, and the error reset.
    EXPECT_TRUE(WaitUntil(
        [&] {
          const auto status = fleet().Status();
          const auto* n = fleet().Node(status, encoder);
          return n->emcy_count() >= before + 2 && n->controller() == "error-active";
        },
        kProductPatience))
        << fleet().Log();
    EXPECT_TRUE(WaitLog(EmcyLine(encoder, 0x8140, 0x01, "00 00 00 00 00"))) << fleet().Log();
    // 00008140h left 1003h with the reset (README "EMCY codes": an entry leaves when its error clears).
    EXPECT_EQ(Sdo(encoder, "0x1003", 0, "u8"), 0u) << encoder;
    EXPECT_EQ(Sdo(encoder, "0x1001", 0, "u8"), 0u) << encoder;
  }
  // C3-1.2.11: encoder-b pre-operational with OUT1 off (choice 7); encoder-a unchanged.
  EXPECT_TRUE(WaitNmt("encoder-b", "pre-operational"));
  EXPECT_TRUE(WaitIo("encoder-b", kOut1, 0)) << IoText("encoder-b", kOut1);
  EXPECT_TRUE(HoldsFor([&] { return NmtOf("encoder-a") == "operational" && Reads("encoder-a", kOut1, 1000); },
                       kNoChangeWindow, kNoChangeReason))
      << NmtOf("encoder-a") << ", OUT1 " << IoText("encoder-a", kOut1);

  ASSERT_TRUE(Cli({"nmt", "start", "encoder-b"}));
  EXPECT_TRUE(WaitNmt("encoder-b", "operational"));
  EXPECT_TRUE(WaitIo("encoder-b", kOut1, 1000)) << IoText("encoder-b", kOut1);
}

}  // namespace
}  // namespace canfleet::system_test
