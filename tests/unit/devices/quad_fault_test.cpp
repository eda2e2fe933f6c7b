// Fault handling of the Quad (AX020506 §4): input range errors and output load faults through the
// pending → active life cycle with their delays, EMCY frames and 1003h entries byte for byte
// ((description << 24) | (channel << 16) | code), 1001h bit 0, the 1029h reactions, the
// controller fault state with its output reactions (6206h/6207h, 6340h/7341h), lost heartbeats.
#include "tests/unit/devices/quad_fixture.hpp"

namespace canfleet::devices::test {
namespace {

class QuadFaultTest : public QuadTest {
 protected:
  /// AIN1 out of range low with error checking on and the given delay.
  void MakeAin1Low(std::uint16_t delay_ms) {
    Write(0x20B0, 1, delay_ms, 2);
    Write(0x20A0, 1, 0x01, 1);
    SetNumber("IN1.voltage_mV", 100);
  }
  std::uint32_t Entry(std::uint8_t sub) { return static_cast<std::uint32_t>(Read(0x1003, sub)); }
};

// §3.3.8-11, §4.1, §4.2: below 2010h for the whole 20B0h delay → FF00h, description 01h,
// channel 1; back in range → error reset, the entry leaves 1003h.
TEST_F(QuadFaultTest, InputBelowErrorMinimumBecomesActiveAfterTheDelay) {
  MakeAin1Low(1000);
  Advance(10ms);  // seen at the sample: pending
  EXPECT_TRUE(Frames("085#").empty());
  Advance(999ms);
  EXPECT_TRUE(Frames("085#").empty());
  EXPECT_EQ(Read(0x1003, 0), 0);
  Advance(1ms);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{Emcy(0xFF00, 0x01, 1, 0x01)});
  EXPECT_EQ(Read(0x1003, 0), 1);
  EXPECT_EQ(Entry(1), 0x0101FF00u);
  EXPECT_EQ(Read(0x1001, 0), 0x01);
  SetNumber("IN1.voltage_mV", 2500);
  Advance(10ms);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{"085#0000000000000000"});
  EXPECT_EQ(Read(0x1003, 0), 0);
  EXPECT_EQ(Read(0x1001, 0), 0);
}

// §4.2: a fault cleared during its delay goes back to inactive; nothing is reported.
TEST_F(QuadFaultTest, AFaultGoneDuringTheDelayIsNeverReported) {
  MakeAin1Low(500);
  Advance(300ms);
  SetNumber("IN1.voltage_mV", 2500);
  Advance(1000ms);
  EXPECT_TRUE(Frames("085#").empty());
  EXPECT_EQ(Read(0x1003, 0), 0);
}

// §3.3.8: above 2080h → FF01h; §3.3.11 a delay of 0 reports at once.
TEST_F(QuadFaultTest, InputAboveErrorMaximumWithZeroDelay) {
  Write(0x20B0, 2, 0, 2);
  Write(0x20A0, 1, 0x02, 1);
  SetNumber("IN2.voltage_mV", 4900);
  Advance(10ms);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{Emcy(0xFF01, 0x01, 2, 0x01)});
  EXPECT_EQ(Entry(1), 0x0102FF01u);
}

// §3.3.10: "If the input is configured as a digital input, error checking is automatically
// disabled."
TEST_F(QuadFaultTest, DigitalInputsAreNotChecked) {
  Write(0x6112, 4, 10, 1);
  Write(0x20B0, 4, 0, 2);
  Write(0x20A0, 1, 0x08, 1);
  Advance(20ms);
  EXPECT_TRUE(Frames("085#").empty());
}

// §4.2: an AI fault applies 1029h sub 3 (2 = stopped).
TEST_F(QuadFaultTest, AnalogInputFaultAppliesErrorBehaviourSub3) {
  Write(0x1029, 3, 2, 1);
  Start();
  MakeAin1Low(0);
  Advance(10ms);
  EXPECT_EQ(stack().State(), canopen::NmtState::kStopped);
}

// §4.1 example: "a short circuit on proportional output channel 3 ... 0x04032320", after the
// 30B0h delay; reaction 1029h sub 5.
TEST_F(QuadFaultTest, ShortCircuitOnPout3IsTheManualsExample) {
  Write(0x1029, 5, 0, 1);
  Start();
  SetEnum("OUT3.load", "short");
  Advance(1000ms);
  EXPECT_TRUE(Frames("085#").empty());
  Advance(1ms);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{"085#2023010304000000"});
  EXPECT_EQ(Entry(1), 0x04032320u);
  EXPECT_EQ(stack().State(), canopen::NmtState::kPreOperational);
}

// §4.1: open circuit 3300h; on a POUT in digital mode the description is 02h (digital output) and
// the delay 300Bh (§3.4.3); on DOUT any fault is FF02h (§4.1 "DOUT only"), channel 05h.
TEST_F(QuadFaultTest, OpenCircuitsByOutputMode) {
  Write(0x30B0, 1, 0, 2);
  Write(0x6310, 2, 1000, 2);
  Write(0x300B, 2, 0, 2);
  Write(0x300B, 5, 0, 2);
  SetEnum("OUT1.load", "open");
  Advance(1ms);
  SetEnum("OUT2.load", "open");
  Advance(1ms);
  SetEnum("OUT5.load", "short");
  Advance(1ms);
  EXPECT_EQ(Frames("085#"), (std::vector<std::string>{"085#0033010104000000", "085#0033010202000000",
                                                      "085#02FF010502000000"}));
  EXPECT_EQ(Read(0x1003, 0), 3);
  EXPECT_EQ(Entry(1), 0x0205FF02u);  // newest first
  EXPECT_EQ(Entry(2), 0x02023300u);
  EXPECT_EQ(Entry(3), 0x04013300u);
  // Repaired: each clears with an error reset; the last one leaves 1001h at 0.
  SetEnum("OUT2.load", "nominal");
  Advance(1ms);
  EXPECT_EQ(Read(0x1003, 0), 2);
  EXPECT_EQ(Entry(1), 0x0205FF02u);
  EXPECT_EQ(Entry(2), 0x04013300u);
}

// §3.1.4: writing 0 to 1003h sub 0 empties the list, but an active error stays active (1001h);
// the list keeps at most 16 errors and drops the oldest.
TEST_F(QuadFaultTest, ErrorListClearsOnRequestAndKeepsSixteen) {
  MakeAin1Low(0);
  Advance(10ms);
  Write(0x1003, 0, 0, 1);
  EXPECT_EQ(Read(0x1003, 0), 0);
  EXPECT_EQ(Read(0x1001, 0), 0x01);
  EXPECT_TRUE(quad().FaultState());
  for (std::uint8_t i = 1; i <= 17; ++i)
    stack().emcy().Raise(quad::MakeErrorEntry(0x3300, 0x04, i));
  EXPECT_EQ(Read(0x1003, 0), 16);
  EXPECT_EQ(Entry(1), 0x04113300u);
  EXPECT_EQ(Entry(16), 0x04023300u);
  EXPECT_EQ(Sdo(SdoRead(0x1003, 17)), SdoAborted(0x1003, 17, 0x06090011));
}

// §4.2 controller fault state with the defaults: 6206h = 1Fh, 6207h = 0 → DOUT off; 6340h = 1,
// 7341h = 0 → POUT 0 mA, and 7341h is written into 7330h. When the fault clears DOUT follows 6200h
// again; POUT1 keeps 7330h = 7341h until the master sends a new value.
TEST_F(QuadFaultTest, FaultStateDrivesOutputsToTheirFaultValues) {
  Start();
  SilenceTpdoTimers();
  Send("305#10");
  Send("205#E803000000000000");
  Advance(1ms);
  ASSERT_TRUE(io().Bool("OUT5.on"));
  ASSERT_EQ(io().Number("OUT1.current_mA"), 1000);
  MakeAin1Low(0);
  Advance(10ms);
  EXPECT_TRUE(quad().FaultState());
  EXPECT_FALSE(io().Bool("OUT5.on"));
  EXPECT_EQ(io().Number("OUT1.current_mA"), 0);
  EXPECT_EQ(Read(0x7330, 1), 0);
  EXPECT_EQ(Read(0x300C, 1), 0);
  SetNumber("IN1.voltage_mV", 2500);
  Advance(10ms);
  EXPECT_FALSE(quad().FaultState());
  EXPECT_TRUE(io().Bool("OUT5.on"));
  EXPECT_EQ(io().Number("OUT1.current_mA"), 0);
  Send("205#E803000000000000");
  Advance(1ms);
  EXPECT_EQ(io().Number("OUT1.current_mA"), 1000);
}

// §3.4.7-8, §3.5.21-22: fault mode 0 keeps operating; fault state bit 1 drives on; a fault FV is
// applied without a ramp even when ramps are on (§3.5.10).
TEST_F(QuadFaultTest, FaultModesAndFaultValuesAreConfigurable) {
  Write(0x6207, 1, 0x10, 1);  // DOUT on in fault state
  Write(0x6206, 1, 0x0F, 1);  // ... no: DOUT keeps operating
  Write(0x7341, 1, 300, 2);
  Write(0x30A0, 1, 1, 1);
  Write(0x6340, 2, 0, 1);
  Start();
  Send("205#0000E80300000000");  // POUT2 1000 mA (ramped: 30A0h.2 = 2 under CAN → no ramp)
  Advance(1ms);
  MakeAin1Low(0);
  Advance(10ms);
  EXPECT_FALSE(io().Bool("OUT5.on"));  // keeps operating: 6200h = 0
  EXPECT_EQ(io().Number("OUT1.current_mA"), 300);
  EXPECT_EQ(io().Number("OUT2.current_mA"), 1000);
  Write(0x6206, 1, 0x1F, 1);
  Advance(1ms);
  EXPECT_TRUE(io().Bool("OUT5.on"));  // driven to 6207h bit 4 = on
}

// §4.2 "Pre-Operational Behaviour": the fault state applies in pre-operational too; "Stopped
// Behaviour": all outputs off, 6206h/6207h/6340h/7341h ignored.
TEST_F(QuadFaultTest, FaultStateInPreOperationalAndStopped) {
  Write(0x6207, 1, 0x10, 1);
  Write(0x7341, 4, 700, 2);
  MakeAin1Low(0);
  Advance(10ms);
  EXPECT_TRUE(io().Bool("OUT5.on"));
  EXPECT_EQ(io().Number("OUT4.current_mA"), 700);
  Send("000#0205");
  Advance(1ms);
  EXPECT_FALSE(io().Bool("OUT5.on"));
  EXPECT_EQ(io().Number("OUT4.current_mA"), 0);
}

// §3.1.7, §4.2: a lost heartbeat is 8130h with description 08h and the node-ID as channel
// (0x08nn8130); 1029h sub 1 = 0 → pre-operational. Its return clears the error.
TEST_F(QuadFaultTest, LostHeartbeatIs08nn8130AndFollows1029hSub1) {
  Write(0x1016, 1, 0x00030064, 4);  // node 3, 100 ms
  Start();
  SilenceTpdoTimers();
  Send("703#05");
  Advance(99ms);
  EXPECT_TRUE(Frames("085#").empty());
  Advance(1ms);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{"085#3081010308000000"});
  EXPECT_EQ(Entry(1), 0x08038130u);
  EXPECT_EQ(stack().State(), canopen::NmtState::kPreOperational);
  Send("703#05");
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{"085#0000000000000000"});
  EXPECT_EQ(Read(0x1003, 0), 0);
}

// §4.2: with 1029h sub 1 = 1 the node stays operational, but the lost heartbeat is an active
// fault: the outputs go to their fault state (the master is gone).
TEST_F(QuadFaultTest, LostHeartbeatWithoutStateChangeStillSetsTheFaultState) {
  Write(0x1016, 2, 0x00070032, 4);  // node 7, 50 ms
  Write(0x1029, 1, 1, 1);
  Start();
  Send("305#10");
  Send("707#05");
  Advance(1ms);
  ASSERT_TRUE(io().Bool("OUT5.on"));
  Advance(50ms);
  EXPECT_EQ(stack().State(), canopen::NmtState::kOperational);
  EXPECT_EQ(Entry(1), 0x08078130u);
  EXPECT_FALSE(io().Bool("OUT5.on"));
}

// §4.2 "Upon reset of the controller, all possible faults ... are in the inactive state": a reset
// empties the list; a fault still present goes through its delay again.
TEST_F(QuadFaultTest, ResetNodeMakesFaultsInactiveAgain) {
  MakeAin1Low(0);
  Advance(10ms);
  EXPECT_EQ(Read(0x1003, 0), 1);
  Send("000#8105");
  EXPECT_EQ(Read(0x1003, 0), 0);
  // The reset restored 20A0h = 0: the low input is no fault any more.
  Advance(20ms);
  EXPECT_EQ(Read(0x1003, 0), 0);
  EXPECT_FALSE(quad().FaultState());
}

}  // namespace
}  // namespace canfleet::devices::test
