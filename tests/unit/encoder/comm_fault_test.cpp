// The three communication faults the orchestrator injects, on the AX023241 (no EMCY table in its
// manual: the family's codes, README.md "EMCY codes"; 1001h bit 0 only, C3-1.2.2; 1003h keeps 15,
// C3-1.2.4; 1029h sub 1 "State transition on Comm. fault", C3-1.2.11): heartbeat loss 80nn8130h,
// RPDO timeout 00008100h, bus-off 00008140h, with their output reactions.
#include "tests/unit/encoder/encoder_fixture.hpp"

namespace canfleet::devices::encoder::test {
namespace {

class CommFaultTest : public EncoderTest {
 protected:
  void DriveOutput1At1000() {
    Write(0x2330, 1, 0, 2);
    SilenceTpdo1();
    Start();
    Send("205#E8030000");
    Advance(1ms);
    ASSERT_EQ(Out("OUT1.current_mA"), 1000);
    Frames();
  }
};

// C3-1.2.7: node 3's heartbeat watched at 100 ms; silence -> EMCY 8130h with the family's
// manufacturer bytes (node 03h, description 80h), 1003h 80038130h, 1001h 01h; 1029h sub 1 = 0
// -> pre-operational, where the CAN controlled output is off.
TEST_F(CommFaultTest, HeartbeatLoss) {
  Write(0x1029, 1, 0, 1);
  Write(0x1016, 1, 0x00030064, 4);
  DriveOutput1At1000();
  Send("703#05");
  Advance(99ms);
  EXPECT_TRUE(Frames("085#").empty());
  Advance(1ms);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{Emcy(0x8130, 3, 0x80)});
  EXPECT_EQ(Read(0x1003, 0), 1);
  EXPECT_EQ(Read(0x1003, 1), 0x80038130);
  EXPECT_EQ(Read(0x1001, 0), 1);
  EXPECT_EQ(stack().State(), canopen::NmtState::kPreOperational);
  Advance(1ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 0);
  Send("703#05");  // back: the error ends
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{"085#0000000000000000"});
  EXPECT_EQ(Read(0x1001, 0), 0);
}

// The default 1029h sub 1 = 1 ("no change", C3-1.2.11): the node stays operational and the output
// keeps its value.
TEST_F(CommFaultTest, HeartbeatLossWithTheDefaultBehaviourChangesNothing) {
  Write(0x1016, 1, 0x00030064, 4);
  DriveOutput1At1000();
  Send("703#05");
  Advance(150ms);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{Emcy(0x8130, 3, 0x80)});
  EXPECT_EQ(stack().State(), canopen::NmtState::kOperational);
  EXPECT_EQ(Out("OUT1.current_mA"), 1000);
}

// C3-1.2.12 sub 5: RPDO1 with a 100 ms event timer; no RPDO for 100 ms -> EMCY 8100h, 1003h
// 00008100h; 7300h.1 is then in error as the control source, and output 1 takes its control fault
// response (6340h = 1: the fault value 7341h, 500 mA). The next RPDO ends the error.
TEST_F(CommFaultTest, RpdoTimeoutAppliesTheControlFaultResponse) {
  Write(0x1400, 5, 100, 2);
  Write(0x6340, 1, 1, 1);
  DriveOutput1At1000();  // the RPDO came 1 ms ago
  Advance(98ms);
  EXPECT_TRUE(Frames("085#").empty());
  Advance(1ms);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{Emcy(0x8100, 0, 0x00)});
  EXPECT_EQ(Read(0x1003, 1), 0x00008100);
  EXPECT_EQ(stack().State(), canopen::NmtState::kOperational);
  Advance(1ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 500);
  Send("205#D0070000");
  Advance(1ms);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{"085#0000000000000000"});
  EXPECT_EQ(Out("OUT1.current_mA"), 2000);
}

// With the default 6340h = 0 the output shuts off; output 2 (7300h.2, the same RPDO) too.
TEST_F(CommFaultTest, RpdoTimeoutShutsOffByDefault) {
  Write(0x1400, 5, 100, 2);
  DriveOutput1At1000();
  Advance(101ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 0);
}

// Bus-off with the default 1029h sub 1 (no change): 8140h in 1003h (00008140h); the EMCY could not
// be sent during bus-off and goes out after recovery, then the error reset, which removes the entry
// (README "EMCY codes": an entry leaves when its error clears; C3-1.2.4); outputs keep going.
TEST_F(CommFaultTest, BusOffIsReportedAfterRecovery) {
  DriveOutput1At1000();
  node_port_.SetControllerState({ControllerState::kBusOff, 256, 0});
  EXPECT_EQ(od().GetUnsigned(0x1003, 1), 0x00008140u);
  EXPECT_EQ(od().GetUnsigned(0x1001, 0), 1u);
  Advance(100ms);
  node_port_.SetControllerState({ControllerState::kErrorActive, 0, 0});
  Advance(10ms);
  EXPECT_EQ(Frames("085#"), (std::vector<std::string>{Emcy(0x8140, 0, 0x00), "085#0000000000000000"}));
  EXPECT_EQ(Read(0x1003, 0), 0);
  EXPECT_EQ(Read(0x1001, 0), 0);
  EXPECT_EQ(stack().State(), canopen::NmtState::kOperational);
  EXPECT_EQ(Out("OUT1.current_mA"), 1000);
}

// 1029h sub 1 = 2: bus-off stops the node, and every output is off in stopped.
TEST_F(CommFaultTest, BusOffStopsTheNodeBy1029h) {
  Write(0x1029, 1, 2, 1);
  DriveOutput1At1000();
  node_port_.SetControllerState({ControllerState::kBusOff, 256, 0});
  EXPECT_EQ(stack().State(), canopen::NmtState::kStopped);
  Advance(1ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 0);
  node_port_.SetControllerState({ControllerState::kErrorActive, 0, 0});
  Advance(10ms);
  EXPECT_EQ(od().GetUnsigned(0x1003, 0), 0u);  // the error cleared; the node stays stopped
  EXPECT_EQ(Out("OUT1.current_mA"), 0);
}

// C3-1.2.4: 1003h keeps the 15 newest errors; writing 0 to sub 0 clears the list.
TEST_F(CommFaultTest, ErrorHistoryIsFifteenDeep) {
  for (std::uint8_t n = 1; n <= 16; ++n)
    stack().emcy().Raise(canopen::ErrorEntry{0xF001, static_cast<std::uint16_t>(0x4000 | n), 1, {}});
  EXPECT_EQ(Read(0x1003, 0), 15);
  EXPECT_EQ(Read(0x1003, 1), 0x4010F001);
  EXPECT_EQ(Read(0x1003, 15), 0x4002F001);
  Write(0x1003, 0, 0, 1);
  EXPECT_EQ(Read(0x1003, 0), 0);
}

}  // namespace
}  // namespace canfleet::devices::encoder::test
