// The output state machine of the PS-24-24-350W-CAN (UMAX080311 §1.2.1): source selection
// (Table 1, Table 2), the enable-pin deglitch (§1.2.1.2), the delayed shutdown with its EMCY and
// acknowledge (§1.2.1.1, 2301h-2303h, RPDO3). The loop samples every 1 ms: a change made between
// two loop instants is seen at the next one.
#include "tests/unit/power_supply/ps_fixture.hpp"

namespace canfleet::devices::test {
namespace {

class PsOutputTest : public PsTest {
 protected:
  bool On() { return io().Bool("PS.output_on"); }
  /// RPDO1 (§2.2.14: 6200h.2 on/off, 6200h.3 quit failure) with `on_off` and no quit.
  void Rpdo1(std::uint8_t on_off) { Send("27F#" + LeHex(on_off, 1) + "FF"); }
};

// Table 1, 6010h.1 = FFh (default): with 6200h.2 = FFh (Table 2 "If 6010h subindex 1 is set to
// 0xFF, output state will be determined by the Remote Enable Signal") the pin switches the output.
TEST_F(PsOutputTest, ByDefaultTheEnablePinSwitchesTheOutput) {
  EXPECT_FALSE(On());
  EXPECT_EQ(State(), "off");
  Enable(true);
  Advance(1ms);
  EXPECT_TRUE(On());
  EXPECT_EQ(State(), "on");
  EXPECT_DOUBLE_EQ(io().Number("VOUT.voltage_mV"), 24000);
  EXPECT_DOUBLE_EQ(io().Number("IOUT.current_mA"), 1000);  // 24 ohm default load
  Advance(1ms);                                            // measured on the next pass (§1.2.3)
  EXPECT_EQ(Read(0x6204, 1), 24000);
  EXPECT_EQ(Read(0x6204, 2), 1000);
  Enable(false);
  Advance(100ms);  // seen at the next pass, then 2310h = 100 ms of deglitch
  EXPECT_TRUE(On());
  Advance(1ms);
  EXPECT_FALSE(On());
  Advance(1ms);
  EXPECT_EQ(Read(0x6204, 1), 0);
}

// Table 1, FFh: "Output is controlled by both sources, following whichever change occurred most
// recently". A repeated 6200h.2 value is no change (README choice 2).
TEST_F(PsOutputTest, BothSourcesTheLatestChangeWins) {
  Start();
  Enable(true);
  Advance(1ms);
  ASSERT_TRUE(On());
  Rpdo1(0xFC);  // CAN off: a change
  Advance(1ms);
  EXPECT_FALSE(On());
  EXPECT_EQ(io().Enum("ENABLE.level"), "high");
  Rpdo1(0xFC);  // the same value again: no change, still off
  Advance(5ms);
  EXPECT_FALSE(On());
  Enable(false);  // a pin change that ends low: off stays off
  Advance(200ms);
  Enable(true);  // the newest change: on
  Advance(1ms);
  EXPECT_TRUE(On());
  Rpdo1(0xFF);  // Table 2 FFh "Output will remain in previous state"
  Advance(1ms);
  EXPECT_TRUE(On());
  Rpdo1(0xFC);
  Advance(1ms);
  EXPECT_FALSE(On());
  Rpdo1(0xFD);
  Advance(1ms);
  EXPECT_TRUE(On());
  EXPECT_TRUE(io().Bool("PS.commanded_on"));
}

// Table 1, FCh "Local Command": "Output is controlled by the Digital Enable Signal, PS Output
// Command CAN frame ignored" (§2.3.1's "252 (remote)" contradicts it: README choice 1).
TEST_F(PsOutputTest, LocalCommandFollowsOnlyThePin) {
  Write(0x6010, 1, 0xFC, 1);
  Write(0x6200, 2, 0xFD, 1);
  Advance(5ms);
  EXPECT_FALSE(On());
  Enable(true);
  Advance(1ms);
  EXPECT_TRUE(On());
  Write(0x6200, 2, 0xFC, 1);
  Advance(5ms);
  EXPECT_TRUE(On());
}

// Table 1, FDh "Remote Command": "Output is controlled by the PS Output Command, Digital Enable
// Signal ignored"; Table 2: FCh off, FDh on, FFh keeps the previous state.
TEST_F(PsOutputTest, RemoteCommandFollowsOnly6200hSub2) {
  Write(0x6010, 1, 0xFD, 1);
  Enable(true);
  Advance(5ms);
  EXPECT_FALSE(On());
  Write(0x6200, 2, 0xFD, 1);
  Advance(1ms);
  EXPECT_TRUE(On());
  Enable(false);
  Advance(200ms);
  EXPECT_TRUE(On());
  Write(0x6200, 2, 0xFF, 1);
  Advance(1ms);
  EXPECT_TRUE(On());
  Write(0x6200, 2, 0xFC, 1);
  Advance(1ms);
  EXPECT_FALSE(On());
}

// §1.2.1.2: "The controller will not read a LOW pin state (and thus command the power supply
// OFF) until the time set in this object has elapsed." A shorter low is a glitch.
TEST_F(PsOutputTest, EnablePinDeglitch) {
  Write(0x2310, 0, 50, 2);
  Enable(true);
  Advance(1ms);
  ASSERT_TRUE(On());
  Enable(false);
  Advance(40ms);
  Enable(true);
  Advance(100ms);
  EXPECT_TRUE(On());
  Enable(false);
  Advance(50ms);  // low seen at +1 ms, read as low 50 ms later
  EXPECT_TRUE(On());
  Advance(1ms);
  EXPECT_FALSE(On());
  // 2310h = 0: the low is read at once.
  Write(0x2310, 0, 0, 2);
  Enable(true);
  Advance(1ms);
  ASSERT_TRUE(On());
  Enable(false);
  Advance(1ms);
  EXPECT_FALSE(On());
}

// §1.2.1.1: 2302h = 0 (default): "output off at once"; no EMCY.
TEST_F(PsOutputTest, WithoutShutdownDelayTheOutputGoesOffAtOnce) {
  OnByCan();
  ASSERT_TRUE(On());
  Write(0x6200, 2, 0xFC, 1);
  Advance(1ms);
  EXPECT_FALSE(On());
  EXPECT_TRUE(Frames("0FF#").empty());
}

// §1.2.1.1, Fig. 1, Table 9: 2302h ≠ 0 → countdown, EMCY F001h "Shutdown Initialized", 1003h
// 2000F001h; the output stays on until the countdown has elapsed, then the error resets.
TEST_F(PsOutputTest, DelayedShutdownSendsF001AndSwitchesOffAfter2302h) {
  Write(0x2302, 0, 1000, 4);
  OnByCan();
  Write(0x6200, 2, 0xFC, 1);
  Advance(1ms);
  EXPECT_EQ(Frames("0FF#"), std::vector<std::string>{Emcy(0xF001, 0x01, 0x00, 0x20)});
  EXPECT_EQ(Read(0x1003, 0), 1);
  EXPECT_EQ(Entry(1), 0x2000F001u);
  EXPECT_EQ(Read(0x1001, 0), 1);
  EXPECT_EQ(State(), "shutdown_delay");
  EXPECT_TRUE(On());
  EXPECT_FALSE(io().Bool("PS.commanded_on"));
  Advance(999ms);
  EXPECT_TRUE(On());
  EXPECT_TRUE(Frames("0FF#").empty());
  Advance(1ms);
  EXPECT_FALSE(On());
  EXPECT_EQ(State(), "off");
  EXPECT_EQ(Frames("0FF#"), std::vector<std::string>{EmcyReset()});
  EXPECT_EQ(Read(0x1003, 0), 0);
  EXPECT_EQ(Read(0x1001, 0), 0);
}

// §1.2.1.1: "connected ECUs can optionally send an acknowledge message to the PDO mappable object
// 2301h PS Shutdown Acknowledge (Mapped to RPDO3 by default). If this message is received with
// value 0x01, the countdown timer will be updated to the value set by object 2303h".
TEST_F(PsOutputTest, AcknowledgeOverRpdo3ShortensTheCountdownTo2303h) {
  Write(0x2302, 0, 5000, 4);
  Write(0x2303, 0, 200, 4);
  Write(0x1402, 1, 0x4000047F, 4);  // RPDO3 exists (§2.2.14: C0000000h + 400h + node-ID by default)
  Start();
  OnByCan();
  Write(0x6200, 2, 0xFC, 1);
  Advance(1000ms);
  ASSERT_EQ(State(), "shutdown_delay");
  Send("47F#01");
  EXPECT_EQ(Read(0x2301, 0), 1);
  Advance(199ms);
  EXPECT_TRUE(On());
  Advance(1ms);
  EXPECT_FALSE(On());
  EXPECT_EQ(Frames("0FF#"), (std::vector<std::string>{Emcy(0xF001, 0x01, 0x00, 0x20), EmcyReset()}));
}

// §1.2.1.1: "If the current countdown is already lower than the time set in object 2303h, then no
// change will occur." An acknowledge outside a countdown does nothing.
TEST_F(PsOutputTest, AcknowledgeNeverLengthensTheCountdown) {
  Write(0x2302, 0, 300, 4);
  Write(0x2303, 0, 1000, 4);
  Write(0x2301, 0, 1, 1);  // no countdown running: nothing happens
  OnByCan();
  ASSERT_TRUE(On());
  Write(0x6200, 2, 0xFC, 1);
  Advance(1ms);
  EXPECT_EQ(Read(0x2301, 0), 0);  // a new countdown waits for a new acknowledge
  Advance(100ms);
  Write(0x2301, 0, 1, 1);
  Advance(199ms);
  EXPECT_TRUE(On());
  Advance(1ms);
  EXPECT_FALSE(On());
}

// Fig. 1's "Command HI" path: an ON command during the countdown keeps the output on and ends the
// shutdown event (README choice 4).
TEST_F(PsOutputTest, OnDuringTheCountdownCancelsIt) {
  Write(0x2302, 0, 1000, 4);
  OnByCan();
  Write(0x6200, 2, 0xFC, 1);
  Advance(500ms);
  Write(0x6200, 2, 0xFD, 1);
  Advance(1ms);
  EXPECT_EQ(State(), "on");
  EXPECT_EQ(Frames("0FF#"), (std::vector<std::string>{Emcy(0xF001, 0x01, 0x00, 0x20), EmcyReset()}));
  Advance(2000ms);
  EXPECT_TRUE(On());
}

// §1.2.1.1 "this applies to both CAN and the Enable Pin" and §1.2.1.2 "This delay is in addition
// to any configured shutdown delay": pin low → 100 ms deglitch, then the 2302h countdown.
TEST_F(PsOutputTest, PinOffAddsDeglitchAndShutdownDelay) {
  Write(0x2302, 0, 400, 4);
  Enable(true);
  Advance(1ms);
  Enable(false);
  Advance(100ms);
  EXPECT_TRUE(Frames("0FF#").empty());
  Advance(1ms);
  EXPECT_EQ(Frames("0FF#"), std::vector<std::string>{Emcy(0xF001, 0x01, 0x00, 0x20)});
  Advance(399ms);
  EXPECT_TRUE(On());
  Advance(1ms);
  EXPECT_FALSE(On());
}

// An OFF command while the output is already off starts no countdown and sends nothing.
TEST_F(PsOutputTest, OffWhileOffIsNoShutdown) {
  Write(0x2302, 0, 1000, 4);
  Write(0x6200, 2, 0xFC, 1);
  Advance(5ms);
  EXPECT_TRUE(Frames("0FF#").empty());
  EXPECT_EQ(State(), "off");
}

}  // namespace
}  // namespace canfleet::devices::test
