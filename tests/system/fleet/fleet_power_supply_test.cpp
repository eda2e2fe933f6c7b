// Issue 19: the three faults the orchestrator injects, end to end on a power-supply-24v-350w
// (UMAX080311) node under `canfleet up` with real processes; a Quad controller (quad-5) is the
// other party (heartbeat producer, and the remote ON command in its TPDO1), the orchestrator the
// master.
//
// Manual references (../shared/seeds/power-supply-24v-350w_UMAX080311.txt):
// - §2.2.4 Table 9: 80nn8130h heartbeat timeout of node nn (EMCY 8130h), 00008100h RPDO timeout
//   (8100h), 00008140h bus-off (EMCY column 8400h is not a CiA code: 8140h, README choice 5);
//   §2.2.2: 1001h bit 0 only; EMCY data bytes channel, description (family_error_policy.hpp).
// - §2.2.13: 1029h sub 1 "Communication Fault" default 0 = pre-operational, for a lost heartbeat
//   and for an RPDO not received within its event timer (§2.2.14; README choice 6: sub 1, not the
//   "sub-index 4" §2.2.14 names); bus-off the same (README choice 5).
// - README choice 15: communication faults leave the output as it is (the manual disables the
//   output only for CiA 453 faults; the supply also runs stand-alone, §1.3).
// - §1.2.1 Table 1 (6010h.1 = FFh default: whichever command changed last) and §2.3.16 (6200h.2
//   FDh = on), RPDO1 §2.2.14 (6200h.2, 6200h.3): the ON command arrives by PDO.
// FleetPowerSupplySequenceTest: the issue's realistic sequence (on by CAN, current limit, latched
// output and input failures, Quit Failure, delayed shutdown with and without the acknowledge).
#include <gtest/gtest.h>

#include "tests/system/fleet/product_fleet_test.hpp"

namespace canfleet::system_test {
namespace {

// quad-5's TPDO1 carries AIN1 only (1A00h.0 = 1, written while the PDO is invalid, CiA 301
// §7.2.2.4), 2 bytes as the supply's RPDO1 (6200h.2, 6200h.3): AIN1 = 253 mV = 00FDh puts FDh
// (switch on) in 6200h.2; 00h in 6200h.3 is not a command (refused, the PDO's other object is
// still written, CiA 301 §7.2.2). The supply's RPDO1 has a 500 ms deadline (1400h.5).
constexpr const char* kTopology = R"(
name: "fleet-test"
bus { name: "can0" bitrate: 250000 }
node { name: "quad-5" device: "quad-controller" node_id: 5 bus: "can0"
       io { key: "IN1.voltage_mV" value: "253" }
       sdo { index: 0x1800 subindex: 1 type: "u32" value: "0x80000185" }
       sdo { index: 0x1A00 subindex: 0 type: "u8" value: "1" }
       sdo { index: 0x1800 subindex: 1 type: "u32" value: "0x185" }
       heartbeat { producer_ms: 200 } }
node { name: "psu" device: "power-supply-24v-350w" node_id: 50 bus: "can0"
       heartbeat { producer_ms: 200 consumer { node: "quad-5" timeout_ms: 1000 } }
       sdo { index: 0x1400 subindex: 1 type: "u32" value: "0x80000185" }
       sdo { index: 0x1400 subindex: 1 type: "u32" value: "0x185" }
       sdo { index: 0x1400 subindex: 5 type: "u16" value: "500" } }
)";

class FleetPowerSupplyTest : public ProductFleetTest {
 protected:
  void SetUp() override {
    StartFleet(kTopology, {"quad-5", "psu"}, "quad-5");
    if (HasFatalFailure()) return;
    // The ON command by PDO switches the output on: 24 V (6205h.1) into the default 24 ohm load.
    ASSERT_TRUE(WaitUntil([&] { return IoText("psu", "PS.output_on") == "true"; }, kProductPatience))
        << IoText("psu", "PS.state");
    ASSERT_TRUE(WaitIo("psu", "VOUT.voltage_mV", 24000)) << IoText("psu", "VOUT.voltage_mV");
  }

  /// README choice 15: the output stays on and regulating after the fault.
  void ExpectOutputUnchanged() {
    EXPECT_TRUE(HoldsFor(
        [&] {
          return IoText("psu", "PS.output_on") == "true" && IoText("psu", "PS.state") == "on" &&
                 Reads("psu", "VOUT.voltage_mV", 24000);
        },
        kNoChangeWindow, kNoChangeReason))
        << IoText("psu", "PS.state") << ", " << IoText("psu", "VOUT.voltage_mV");
  }
};

TEST_F(FleetPowerSupplyTest, HeartbeatLossRaises80nn8130hGoesPreOperationalOutputStaysOn) {
  ASSERT_TRUE(Cli({"fault", "inject", "heartbeat-loss", "--node", "quad-5"}));
  ExpectErrorRecorded("psu", 0x8130, "05 80 00 00 00", 0x80058130u);
  EXPECT_TRUE(WaitUntil([&] { return LastEmcyOf("psu") == 0x8130u; }, kProductPatience));
  EXPECT_TRUE(WaitNmt("psu", "pre-operational"));  // §2.2.13, default 0
  ExpectOutputUnchanged();

  ASSERT_TRUE(Cli({"fault", "clear", "--all"}));
  EXPECT_TRUE(WaitUntil([&] { return LastEmcyOf("psu") == 0x0000u; }, kProductPatience));
  EXPECT_EQ(Sdo("psu", "0x1001", 0, "u8"), 0u);
  ASSERT_TRUE(Cli({"nmt", "start", "psu"}));
  EXPECT_TRUE(WaitNmt("psu", "operational"));
  ExpectOutputUnchanged();
}

TEST_F(FleetPowerSupplyTest, RpdoTimeoutRaises00008100hGoesPreOperationalOutputStaysOn) {
  ASSERT_TRUE(Cli({"fault", "inject", "rpdo-timeout", "--node", "psu", "--cob-id", "0x185"}));
  ExpectErrorRecorded("psu", 0x8100, "00 00 00 00 00", 0x00008100u);
  EXPECT_TRUE(WaitNmt("psu", "pre-operational"));
  ExpectOutputUnchanged();
  EXPECT_EQ(NmtOf("quad-5"), "operational");  // only the supply misses 185h

  ASSERT_TRUE(Cli({"fault", "clear", "--all"}));
  ASSERT_TRUE(Cli({"nmt", "start", "psu"}));
  EXPECT_TRUE(WaitNmt("psu", "operational"));
  // RPDO1 arrives again: the deadline error clears.
  EXPECT_TRUE(WaitUntil([&] { return LastEmcyOf("psu") == 0x0000u; }, kProductPatience));
  ExpectOutputUnchanged();
}

TEST_F(FleetPowerSupplyTest, BusOffSends8140hAfterRecoveryGoesPreOperationalOutputStaysOn) {
  const auto before = EmcyCountOf("psu");
  ASSERT_TRUE(Cli({"fault", "inject", "bus-off", "--node", "psu"}));
  // Automatic recovery; the 8140h "recovered from bus-off" leaves then, and the error reset.
  EXPECT_TRUE(WaitUntil(
      [&] {
        const auto status = fleet().Status();
        const auto* n = fleet().Node(status, "psu");
        return n->emcy_count() >= before + 2 && n->controller() == "error-active";
      },
      kProductPatience))
      << fleet().Log();
  EXPECT_TRUE(WaitLog(EmcyLine("psu", 0x8140, 0x01, "00 00 00 00 00"))) << fleet().Log();
  // §2.2.4: the entry "is immediately removed when the error condition has been cleared".
  EXPECT_EQ(Sdo("psu", "0x1003", 0, "u8"), 0u);
  EXPECT_EQ(Sdo("psu", "0x1001", 0, "u8"), 0u);
  EXPECT_TRUE(WaitNmt("psu", "pre-operational"));
  ExpectOutputUnchanged();

  ASSERT_TRUE(Cli({"nmt", "start", "psu"}));
  EXPECT_TRUE(WaitNmt("psu", "operational"));
}

// Issue 19's realistic sequence, the orchestrator as the master (its SDO writes): supply on by CAN,
// load stepped up into the current limit, an output failure latched until Quit Failure, the input
// voltage below its threshold (failure flags, EMCY, latch), Quit Failure, and the delayed shutdown
// without and with the acknowledge. 2320h = 1 latches failures (§2.4.9); 2303h = 500 ms (§2.4.6).
constexpr const char* kSequenceTopology = R"(
name: "fleet-test"
bus { name: "can0" bitrate: 250000 }
node { name: "psu" device: "power-supply-24v-350w" node_id: 50 bus: "can0"
       io { key: "LOAD.resistance_ohm" value: "4" }
       heartbeat { producer_ms: 200 }
       sdo { index: 0x2320 subindex: 0 type: "u8" value: "1" }
       sdo { index: 0x2303 subindex: 0 type: "u32" value: "500" } }
)";

class FleetPowerSupplySequenceTest : public ProductFleetTest {
 protected:
  void SetUp() override { StartFleet(kSequenceTopology, {"psu"}, "psu"); }

  bool Write(const std::string& index, int sub, const std::string& type, const std::string& value) {
    return Cli({"sdo", "write", "psu", index, std::to_string(sub), type, value});
  }
  bool Set(const std::string& name, const std::string& value) {
    return Cli({"io", "set", "psu", name, value});
  }
  bool WaitState(const std::string& state) const {
    return WaitUntil([&] { return IoText("psu", "PS.state") == state; }, kProductPatience);
  }
};

TEST_F(FleetPowerSupplySequenceTest, OnByCanCurrentLimitLatchedFailuresQuitFailureDelayedShutdown) {
  // §2.3.16: 6200h.2 = FDh switches the output on (6010h.1 = FFh: the latest command, Table 1).
  ASSERT_TRUE(Write("0x6200", 2, "u8", "0xFD"));
  ASSERT_TRUE(WaitState("on"));
  EXPECT_TRUE(WaitIo("psu", "IOUT.current_mA", 6000)) << IoText("psu", "IOUT.current_mA");  // 24 V / 4 ohm

  // §1.2.1.3 Fig. 2 (README choice 8): 15 A at and above 18 V input; 1 ohm wants 24 A and gets 15 A
  // at 15 V. The output current threshold 2 moved above it first (6205h.12/.42), so no failure.
  ASSERT_TRUE(Write("0x6205", 12, "i32", "20000"));
  ASSERT_TRUE(Write("0x6205", 42, "i32", "20000"));
  ASSERT_TRUE(Set("LOAD.resistance_ohm", "1"));
  EXPECT_TRUE(WaitUntil([&] { return IoText("psu", "PS.current_limited") == "true"; }, kProductPatience));
  EXPECT_TRUE(WaitIo("psu", "IOUT.current_mA", 15000)) << IoText("psu", "IOUT.current_mA");
  EXPECT_TRUE(WaitIo("psu", "VOUT.voltage_mV", 15000)) << IoText("psu", "VOUT.voltage_mV");
  EXPECT_FALSE(LastEmcyOf("psu").has_value());

  // Back to the manual's 13 A: above it for 6205h.14 + 6013h.2, the output failure FF06h (Table 9);
  // the output goes off and, 2320h = 1, stays off although the failure ends with the current.
  ASSERT_TRUE(Write("0x6205", 42, "i32", "13000"));
  ASSERT_TRUE(Write("0x6205", 12, "i32", "13000"));
  EXPECT_TRUE(WaitLog(EmcyLine("psu", 0xFF06, 0x01, "00 00 00 00 00"))) << fleet().Log();
  EXPECT_TRUE(WaitState("fault_latched"));
  ASSERT_TRUE(Set("LOAD.resistance_ohm", "4"));
  EXPECT_TRUE(HoldsFor([&] { return IoText("psu", "PS.state") == "fault_latched"; }, kNoChangeWindow,
                       "the latch holds until Quit Failure; 7 heartbeat periods for a change to show"));
  // Quit Failure, 6200h.3 = FCh (§1.2.3 Table 6, README choice 3): on again.
  ASSERT_TRUE(Write("0x6200", 3, "u8", "0xFC"));
  EXPECT_TRUE(WaitState("on"));

  // §1.2.3: the input below 6114h (9 V) is an input failure: EMCY FF04h, 1003h 0000FF04h, 1001h bit
  // 0; 6112h Vt1 (bits 1-0): condition 00 (below its return), event and indication 01 (§2.3.9);
  // 6012h "i" (bits 1-0) 01 (§2.3.2); the output off and latched.
  ASSERT_TRUE(Set("VIN.voltage_mV", "8000"));
  EXPECT_TRUE(WaitLog(EmcyLine("psu", 0xFF04, 0x01, "00 00 00 00 00"))) << fleet().Log();
  EXPECT_TRUE(WaitState("fault_latched"));
  EXPECT_EQ(Sdo("psu", "0x1003", 1, "u32"), 0x0000FF04u);
  EXPECT_EQ(Sdo("psu", "0x1001", 0, "u8"), 0x01u);
  EXPECT_EQ(Sdo("psu", "0x6112", 1, "u32").value_or(0) & 0x3, 0x0u);
  EXPECT_EQ(Sdo("psu", "0x6112", 3, "u32").value_or(0) & 0x3, 0x1u);
  EXPECT_EQ(Sdo("psu", "0x6112", 5, "u32").value_or(0) & 0x3, 0x1u);
  EXPECT_EQ(Sdo("psu", "0x6012", 1, "u32").value_or(0) & 0x3, 0x1u);
  // The input recovers: the failure ends (EMCY 0000h, 1001h = 0), the latch stays until Quit Failure.
  ASSERT_TRUE(Set("VIN.voltage_mV", "24000"));
  EXPECT_TRUE(WaitUntil([&] { return LastEmcyOf("psu") == 0x0000u; }, kProductPatience));
  EXPECT_EQ(Sdo("psu", "0x1001", 0, "u8"), 0u);
  EXPECT_EQ(IoText("psu", "PS.state"), "fault_latched");
  ASSERT_TRUE(Write("0x6200", 3, "u8", "0xFC"));
  EXPECT_TRUE(WaitState("on"));

  // §1.2.1.1 (README choice 4): OFF with 2302h = 5 s starts the countdown, EMCY F001h, 1003h
  // 2000F001h; the output stays on until it ends, then goes off and the error ends.
  ASSERT_TRUE(Write("0x2302", 0, "u32", "5000"));
  ASSERT_TRUE(Write("0x6200", 2, "u8", "0xFC"));
  EXPECT_TRUE(WaitLog(EmcyLine("psu", 0xF001, 0x01, "00 20 00 00 00"))) << fleet().Log();
  EXPECT_EQ(IoText("psu", "PS.state"), "shutdown_delay");
  EXPECT_EQ(IoText("psu", "PS.output_on"), "true");
  EXPECT_EQ(Sdo("psu", "0x1003", 1, "u32"), 0x2000F001u);
  EXPECT_TRUE(WaitState("off"));
  EXPECT_TRUE(WaitUntil([&] { return LastEmcyOf("psu") == 0x0000u; }, kProductPatience));

  // With the acknowledge (2301h = 1, §2.4.4): a 60 s countdown ends 2303h = 500 ms after it, long
  // before its base delay (the bound below is half of it).
  ASSERT_TRUE(Write("0x2302", 0, "u32", "60000"));
  ASSERT_TRUE(Write("0x6200", 2, "u8", "0xFD"));
  ASSERT_TRUE(WaitState("on"));
  ASSERT_TRUE(Write("0x6200", 2, "u8", "0xFC"));
  ASSERT_TRUE(WaitState("shutdown_delay"));
  ASSERT_TRUE(Write("0x2301", 0, "u8", "1"));
  EXPECT_TRUE(WaitUntil([&] { return IoText("psu", "PS.state") == "off"; }, std::chrono::seconds(30)));
}

}  // namespace
}  // namespace canfleet::system_test
