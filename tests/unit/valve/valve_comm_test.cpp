// The three communication faults the orchestrator injects, as the valve's manual encodes them
// (UMAX020411A §3.2.4 Table 33, §3.2.13, §3.2.14): heartbeat loss 80nn8130h, RPDO timeout 00008100h,
// bus-off 00008140h; 1001h bit 0 only; the 1029h sub 1 reaction; 1003h keeps 4 entries; an output
// driven by a timed-out RPDO takes its fault reaction (README).
#include "tests/unit/valve/valve_fixture.hpp"

namespace canfleet::devices::valve::test {
namespace {

class ValveCommTest : public ValveTest {
 protected:
  void SetUp() override { SilenceTpdos(); }
};

// §3.2.4: "the Error Description will be set to 0x80 and the Channel-ID (nn) will reflect the
// Node-ID", EMCY 8130h; §3.2.13 sub 1 = 0 -> pre-operational.
TEST_F(ValveCommTest, HeartbeatLoss) {
  Write(0x1016, 1, 0x00030064, 4);  // node 3, 100 ms
  Write(0x1029, 1, 0, 1);
  Start();
  Frames();
  Send("703#05");
  Advance(99ms);
  EXPECT_TRUE(Frames("085#").empty());
  Advance(1ms);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{Emcy(0x8130, 0x01, 3, 0x80)});
  EXPECT_EQ(Read(0x1003, 1), 0x80038130);
  EXPECT_EQ(Read(0x1001, 0), 0x01);  // bit 0 only (§3.2.2)
  EXPECT_EQ(stack().State(), canopen::NmtState::kPreOperational);
}

// §3.2.14: an RPDO event timer expiring in operational -> 00008100h, 1029h sub 1 (2 = stopped).
TEST_F(ValveCommTest, RpdoTimeoutStopsTheNode) {
  Write(0x1400, 5, 100, 2);
  Write(0x1029, 1, 2, 1);
  Start();
  Send("205#0000000000000000");
  Advance(100ms);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{Emcy(0x8100, 0x01, 0, 0x00)});
  EXPECT_EQ(stack().State(), canopen::NmtState::kStopped);
  EXPECT_EQ(od().GetUnsigned(0x1003, 1), 0x00008100u);
}

// README: while RPDO1 is timed out, 7300h.1-4 read as faulted: OUT1 (controlled by 7300h.1) goes
// to 7341h (500 mA, 6340h = 1); a new RPDO ends it.
TEST_F(ValveCommTest, RpdoTimeoutAppliesTheOutputFaultReaction) {
  Write(0x1400, 5, 100, 2);
  Write(0x2330, 1, 0, 2);
  Write(0x2331, 1, 0, 2);
  Start();
  Send("205#8403000000000000");  // 900 mA
  Advance(50ms);
  EXPECT_EQ(Read(0x7330, 1, true), 900);
  Advance(52ms);
  EXPECT_EQ(Read(0x7330, 1, true), 500);
  EXPECT_EQ(Read(0x1003, 1), 0x00008100);
  Send("205#8403000000000000");
  Advance(2ms);
  EXPECT_EQ(Read(0x7330, 1, true), 900);
  EXPECT_EQ(Read(0x1003, 0), 0);
}

// Table 33: bus-off -> 00008140h (the EMCY column's 8400h is not used, README); 1029h sub 1. The
// EMCY goes out after the recovery, then the error reset, which removes the entry (§3.2.4:
// "immediately removed when the error condition has been cleared", sub 0 zero when error-free).
TEST_F(ValveCommTest, BusOff) {
  Write(0x1029, 1, 0, 1);
  Start();
  Frames();
  port().SetControllerState({ControllerState::kBusOff, 256, 0});
  EXPECT_EQ(stack().State(), canopen::NmtState::kPreOperational);
  EXPECT_EQ(od().GetUnsigned(0x1003, 1), 0x00008140u);
  EXPECT_EQ(od().GetUnsigned(0x1001, 0), 0x01u);
  port().SetControllerState({ControllerState::kErrorActive, 0, 0});
  Advance(10ms);
  EXPECT_EQ(Frames("085#"), (std::vector<std::string>{Emcy(0x8140, 0x01, 0, 0x00), "085#0000000000000000"}));
  EXPECT_EQ(Read(0x1003, 0), 0);
  EXPECT_EQ(od().GetUnsigned(0x1001, 0), 0x00u);
}

// §3.2.4: "a maximum of 4 errors in the list ... the oldest entries will be lost".
TEST_F(ValveCommTest, ErrorHistoryKeepsFour) {
  for (std::uint8_t sub = 1; sub <= 5; ++sub)
    Write(0x2112, sub, 0, 2);
  for (int n = 1; n <= 5; ++n)
    SetNumber("IN" + std::to_string(n) + ".voltage_mV", 0);
  Advance(2ms);
  EXPECT_EQ(Read(0x1003, 0), 4);
  EXPECT_EQ(Read(0x1003, 1), 0x4005F001);
  EXPECT_EQ(Read(0x1003, 4), 0x4002F001);
  EXPECT_EQ(Sdo("605#4003100500000000"), SdoAborted(0x1003, 5, 0x08000024));
}

}  // namespace
}  // namespace canfleet::devices::valve::test
