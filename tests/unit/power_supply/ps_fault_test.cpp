// Fault handling of the PS-24-24-350W-CAN (UMAX080311 §1.2.3, §2.2.2-§2.2.4 Table 9, §2.2.13,
// §2.3.2, §2.3.9, §2.3.17, §2.4.9): the CiA 453 failure flags with their thresholds, returns and
// delays, the aggregated EMCY FF04h/FF06h entries, the output reaction, the fault latch (2320h)
// and Quit Failure, 1029h, and the three communication faults of Table 9 (heartbeat, RPDO
// timeout, bus-off) with their 1003h entries.
#include "node/devices/family/family_error_policy.hpp"
#include "tests/unit/power_supply/ps_fixture.hpp"

namespace canfleet::devices::test {
namespace {

const std::string kInputFailure = Emcy(0xFF04, 0x01, 0x00, 0x00);   // Table 9 0000FF04h
const std::string kOutputFailure = Emcy(0xFF06, 0x01, 0x00, 0x00);  // Table 9 0000FF06h

class PsFaultTest : public PsTest {
 protected:
  PsFaultTest() { NoInputFilter(); }
  bool On() { return io().Bool("PS.output_on"); }
  std::uint32_t Read32(std::uint16_t index, std::uint8_t sub) {
    return static_cast<std::uint32_t>(Read(index, sub));
  }
  /// A 1.5 ohm load at 24 V asks 16 A: the output runs at its 15 A limit, above 6205h.12 = 13 A.
  void Overload() { SetNumber("LOAD.resistance_ohm", 1.5); }
};

// §2.3.9 defaults: condition FFF1FFF1h (Vt1 above threshold 1, Vt2 below return 2, Tt1, Tt2
// likewise), logic FFF4FFF4h, event/indication FFF0FFF0h; §2.3.17 FFFFFF11h/74h/00h/55h/00h;
// §2.3.2 6012h FFFFFFF0h and FFFFFFFFh: an idle node at factory defaults has no failure.
TEST_F(PsFaultTest, FactoryDefaultsRaiseNothing) {
  Advance(1s);
  EXPECT_EQ(Read32(0x6112, 1), 0xFFF1FFF1u);
  EXPECT_EQ(Read32(0x6112, 3), 0xFFF0FFF0u);
  EXPECT_EQ(Read32(0x6112, 5), 0xFFF0FFF0u);
  EXPECT_EQ(Read32(0x6202, 1), 0xFFFFFF11u);
  EXPECT_EQ(Read32(0x6202, 3), 0xFFFFFF00u);
  EXPECT_EQ(Read32(0x6012, 1), 0xFFFFFFF0u);
  EXPECT_EQ(Read32(0x6012, 3), 0xFFFFFFFFu);
  OnByCan();
  Advance(1s);
  EXPECT_EQ(Read32(0x6202, 1), 0xFFFFFF11u);
  EXPECT_TRUE(Frames("0FF#").empty());
  EXPECT_EQ(Read(0x1001, 0), 0);
}

// §1.2.3: Vt1 "is triggered when the measured input is below object 611Ah PS Input Return 1";
// 6119h.1 = 100 ms before the event, 6013h.1 = 100 ms before "a fault is detected and an EMCY
// message is sent" (README choice 10); "When a fault occurs, the power supply output is disabled
// and the controller sends an EMCY frame" FF04h. With 2320h = 0 the output comes back when the
// input does (README choice 11).
TEST_F(PsFaultTest, InputUnderVoltageIsFF04AfterBothDelays) {
  OnByCan();
  SetNumber("VIN.voltage_mV", 8800);  // above the 8.5 V hardware shutdown
  Advance(1ms);
  EXPECT_EQ(Read32(0x6112, 1), 0xFFF1FFF0u);  // Vt1 condition 00: lower than return
  EXPECT_EQ(Read32(0x6112, 3), 0xFFF0FFF0u);
  Advance(99ms);
  EXPECT_EQ(Read32(0x6112, 3), 0xFFF0FFF0u);
  Advance(1ms);
  EXPECT_EQ(Read32(0x6112, 3), 0xFFF0FFF1u);  // event on
  EXPECT_EQ(Read32(0x6112, 5), 0xFFF0FFF1u);  // fault state "process" → indication on
  EXPECT_EQ(Read32(0x6012, 1), 0xFFFFFFF1u);  // device: input failure
  EXPECT_TRUE(On());
  Advance(99ms);
  EXPECT_TRUE(Frames("0FF#").empty());
  EXPECT_TRUE(On());
  Advance(1ms);
  EXPECT_EQ(Frames("0FF#"), std::vector<std::string>{kInputFailure});
  EXPECT_FALSE(On());
  EXPECT_EQ(State(), "fault");
  EXPECT_EQ(Read(0x1003, 0), 1);
  EXPECT_EQ(Entry(1), 0x0000FF04u);
  EXPECT_EQ(Read(0x1001, 0), 1);
  EXPECT_EQ(Read(0x6011, 1) & 0x0F, 0x04);  // failure active, output off (README choice 17)

  SetNumber("VIN.voltage_mV", 24000);
  Advance(1ms);
  EXPECT_EQ(Frames("0FF#"), std::vector<std::string>{EmcyReset()});
  EXPECT_EQ(Read(0x1003, 0), 0);
  EXPECT_EQ(Read32(0x6112, 5), 0xFFF0FFF0u);
  EXPECT_EQ(Read32(0x6012, 1), 0xFFFFFFF0u);
  EXPECT_TRUE(On());
  EXPECT_EQ(State(), "on");
}

// A condition gone during the delays is never reported.
TEST_F(PsFaultTest, AShortDipIsNoFailure) {
  OnByCan();
  SetNumber("VIN.voltage_mV", 8800);
  Advance(150ms);
  SetNumber("VIN.voltage_mV", 24000);
  Advance(1s);
  EXPECT_TRUE(Frames("0FF#").empty());
  EXPECT_TRUE(On());
}

// Table 9: "DS-453 Input Failure Status" is one entry, whichever flags (Vt1, Tt2) caused it; it
// stays until the last one clears. §2.3.5-§2.3.8: temperatures in 0.1 degC (700 = 70.0 degC).
TEST_F(PsFaultTest, InputFailuresAggregateIntoOneEntry) {
  OnByCan();
  SetNumber("TEMP.temperature_C", 75.0);
  Advance(201ms);
  EXPECT_EQ(Frames("0FF#"), std::vector<std::string>{kInputFailure});
  EXPECT_EQ(Read32(0x6112, 5), 0xFFF4FFF0u);  // Tt2 (bits 19-18) on
  SetNumber("VIN.voltage_mV", 8800);
  Advance(300ms);
  EXPECT_EQ(Read32(0x6112, 5), 0xFFF4FFF1u);
  EXPECT_TRUE(Frames("0FF#").empty());
  EXPECT_EQ(Read(0x1003, 0), 1);
  SetNumber("TEMP.temperature_C", 25.0);
  Advance(5ms);
  EXPECT_TRUE(Frames("0FF#").empty());
  EXPECT_FALSE(On());
  SetNumber("VIN.voltage_mV", 24000);
  Advance(1ms);
  EXPECT_EQ(Frames("0FF#"), std::vector<std::string>{EmcyReset()});
  EXPECT_TRUE(On());
}

// §1.2.3: "These values can be modified to give the controller an error clear hysteresis": set
// below 611Ah, cleared above 6114h, unchanged in between.
TEST_F(PsFaultTest, ThresholdAndReturnGiveHysteresis) {
  Write(0x6114, 1, 11000, 4);
  OnByCan();
  SetNumber("VIN.voltage_mV", 10000);  // between return 9 V and threshold 11 V: still fine
  Advance(500ms);
  EXPECT_TRUE(Frames("0FF#").empty());
  SetNumber("VIN.voltage_mV", 8800);
  Advance(201ms);
  EXPECT_EQ(Frames("0FF#"), std::vector<std::string>{kInputFailure});
  SetNumber("VIN.voltage_mV", 10000);
  Advance(100ms);
  EXPECT_TRUE(Frames("0FF#").empty());  // in the band: the failure holds
  SetNumber("VIN.voltage_mV", 11000);
  Advance(1ms);
  EXPECT_EQ(Frames("0FF#"), std::vector<std::string>{EmcyReset()});
}

// §1.2.3: Vt2 "triggered when the measured input voltage is above the object 6115h"; at 50 V the
// 44 V hardware protection has already switched the output off (§3), the EMCY follows the delays.
TEST_F(PsFaultTest, InputOverVoltage) {
  OnByCan();
  SetNumber("VIN.voltage_mV", 50000);
  Advance(1ms);
  EXPECT_FALSE(On());
  EXPECT_EQ(State(), "protection");
  Advance(200ms);
  EXPECT_EQ(Frames("0FF#"), std::vector<std::string>{kInputFailure});
  EXPECT_EQ(Read32(0x6112, 5), 0xFFF0FFF4u);
  EXPECT_EQ(State(), "fault");
}

// §2.3.9 sub 4 "Fault State": 11 = ignore. The event is still reported in sub 3, but there is no
// indication, no EMCY and no output reaction.
TEST_F(PsFaultTest, FaultStateIgnoreKeepsTheOutputOn) {
  Write(0x6112, 4, 0xFFF5FFF7, 4);
  OnByCan();
  SetNumber("VIN.voltage_mV", 8800);
  Advance(1s);
  EXPECT_EQ(Read32(0x6112, 3), 0xFFF0FFF1u);
  EXPECT_EQ(Read32(0x6112, 5), 0xFFF0FFF0u);
  EXPECT_TRUE(Frames("0FF#").empty());
  EXPECT_TRUE(On());
}

// §2.3.17: 6205h.12 current threshold 2 = 13000 mA, logic 01, delay 6205h.14 = 100 ms, then 6013h.2
// = 100 ms: FF06h, output off. With 2320h = 0 the output tries again one loop later (no current,
// no failure): the supply hiccups every 200 ms (README choice 11).
TEST_F(PsFaultTest, OutputOverCurrentIsFF06AndHiccupsWithoutLatch) {
  Overload();
  OnByCan();
  Advance(1ms);                               // the 15 A are measured one loop after switching on
  EXPECT_EQ(Read32(0x6202, 1), 0xFFFFFF51u);  // Ct2 (bits 7-6) higher or equal than threshold
  Advance(199ms);
  EXPECT_TRUE(Frames("0FF#").empty());
  Advance(1ms);
  EXPECT_EQ(Frames("0FF#"), std::vector<std::string>{kOutputFailure});
  EXPECT_EQ(Entry(1), 0x0000FF06u);
  EXPECT_EQ(Read32(0x6012, 1), 0xFFFFFFF4u);  // device: output failure (o1)
  EXPECT_FALSE(On());
  Advance(1ms);  // 0 A measured: the failure is gone, the output is on again
  EXPECT_EQ(Frames("0FF#"), std::vector<std::string>{EmcyReset()});
  EXPECT_TRUE(On());
  Advance(200ms);
  EXPECT_TRUE(Frames("0FF#").empty());
  Advance(1ms);
  EXPECT_EQ(Frames("0FF#"), std::vector<std::string>{kOutputFailure});
}

// §1.2.3, §2.4.9, Table 6: with 2320h = 1 "the output will stay disabled, even if commanded ON"
// until "Quit Failure" FCh arrives in 6200h.3 (RPDO1 by default); the 1003h entry goes when the
// failure does (§2.2.4), the latch stays.
TEST_F(PsFaultTest, LatchedFaultWaitsForQuitFailureOnRpdo1) {
  Write(0x2320, 0, 1, 1);
  Overload();
  Start();
  Send("27F#FDFF");
  Advance(1ms);
  ASSERT_TRUE(On());
  Advance(201ms);  // measured from the next loop, 6205h.14 then 6013h.2
  EXPECT_FALSE(On());
  EXPECT_EQ(State(), "fault_latched");
  Advance(10ms);
  EXPECT_EQ(Frames("0FF#"), (std::vector<std::string>{kOutputFailure, EmcyReset()}));
  EXPECT_EQ(Read(0x1001, 0), 0);
  EXPECT_FALSE(On());
  EXPECT_EQ(Read(0x6011, 1) & 0x33, 0x10);  // latched, output off
  Send("27F#FDFF");                         // ON again: the latch holds
  Advance(10ms);
  EXPECT_FALSE(On());
  SetNumber("LOAD.resistance_ohm", 24.0);
  Send("27F#FDFC");  // Quit Failure
  Advance(1ms);
  EXPECT_TRUE(On());
  EXPECT_EQ(State(), "on");
}

// 6010h.2 "PS Quit Failure" (252 = quit) quits the latch too; a quit while the failure is still
// present changes nothing (Table 6: "If the device has entered fault state, the device will
// transition to the regular operation state" only once nothing holds it there).
TEST_F(PsFaultTest, QuitFailureThroughSdoAndWhileStillFailing) {
  Write(0x2320, 0, 1, 1);
  OnByCan();
  SetNumber("VIN.voltage_mV", 8800);
  Advance(201ms);
  ASSERT_EQ(State(), "fault_latched");
  Write(0x6200, 3, 0xFC, 1);
  Advance(5ms);
  EXPECT_EQ(State(), "fault_latched");
  SetNumber("VIN.voltage_mV", 24000);
  Advance(5ms);
  EXPECT_FALSE(On());
  Write(0x6010, 2, 0xFC, 1);
  Advance(1ms);
  EXPECT_TRUE(On());
}

// §2.2.13: "Object 1029h Error Behaviour can ONLY be changed if there are NO errors present":
// refused with 08000022h while 1001h ≠ 0 (README choice 14).
TEST_F(PsFaultTest, ErrorBehaviourIsWritableOnlyWithoutErrors) {
  Write(0x1029, 2, 2, 1);
  SetNumber("VIN.voltage_mV", 8800);
  Advance(201ms);
  ASSERT_EQ(Read(0x1001, 0), 1);
  EXPECT_EQ(TryWrite(0x1029, 3, 2, 1), SdoAborted(0x1029, 3, 0x08000022));
  EXPECT_EQ(TryWrite(0x1029, 1, 1, 1), SdoAborted(0x1029, 1, 0x08000022));
  EXPECT_EQ(Read(0x1029, 3), 1);
  SetNumber("VIN.voltage_mV", 24000);
  Advance(1ms);
  ASSERT_EQ(Read(0x1001, 0), 0);
  Write(0x1029, 3, 2, 1);
  EXPECT_EQ(Read(0x1029, 3), 2);
}

// §2.2.13, 1029h sub 3 "Input Error" = 2 → stopped; sub 4 "Output Error" = 0 → pre-operational.
TEST_F(PsFaultTest, InputFailureFollows1029hSub3) {
  Write(0x1029, 3, 2, 1);
  Start();
  SetNumber("TEMP.temperature_C", -30.0);  // Tt1: below 6025h = -25.0 degC
  Advance(200ms);
  EXPECT_EQ(stack().State(), canopen::NmtState::kOperational);
  Advance(1ms);
  EXPECT_EQ(stack().State(), canopen::NmtState::kStopped);
}

TEST_F(PsFaultTest, OutputFailureFollows1029hSub4) {
  Write(0x1029, 4, 0, 1);
  Start();
  Overload();
  Write(0x6200, 2, 0xFD, 1);
  Advance(201ms);
  EXPECT_EQ(stack().State(), canopen::NmtState::kOperational);
  Advance(1ms);  // on at +1 ms, measured at +2 ms, then 100 + 100 ms
  EXPECT_EQ(Frames("0FF#"), std::vector<std::string>{kOutputFailure});
  EXPECT_EQ(stack().State(), canopen::NmtState::kPreOperational);
}

// §2.2.4: "The Controller has a limitation of a maximum of 4 errors in the list"; 1003h declares
// sub 1-15. Writing 0 to sub 0 clears the list but "does NOT mean that the module will return to
// the error-free behaviour state".
TEST_F(PsFaultTest, ErrorHistoryKeepsFourAndClearingKeepsTheErrorState) {
  SetNumber("VIN.voltage_mV", 8800);
  Advance(201ms);
  for (std::uint8_t n = 1; n <= 4; ++n)
    stack().emcy().Raise(family::MakeFamilyEntry(0x8130, 0x80, n));
  EXPECT_EQ(Read(0x1003, 0), 4);
  EXPECT_EQ(Entry(1), 0x80048130u);
  EXPECT_EQ(Entry(4), 0x80018130u);  // FF04h fell off
  EXPECT_EQ(Sdo(SdoRead(0x1003, 5)), SdoAborted(0x1003, 5, 0x08000024));
  Write(0x1003, 0, 0, 1);
  EXPECT_EQ(Read(0x1003, 0), 0);
  EXPECT_EQ(Read(0x1001, 0), 1);
  EXPECT_FALSE(On());
}

// §2.2.4, §2.2.9, Table 9: a consumer heartbeat that stops is EMCY 8130h with 1003h 80nn8130h (nn =
// the silent node); §2.2.13 1029h sub 1 = 0 → pre-operational. The output is not touched (the
// manual disables it only for DS-453 faults, README choice 15).
TEST_F(PsFaultTest, LostHeartbeatIs80nn8130AndPreOperational) {
  Write(0x1016, 1, 0x00030064, 4);  // node 3, 100 ms
  OnByCan();
  Start();
  Send("703#05");
  Frames();
  Advance(99ms);
  EXPECT_TRUE(Frames("0FF#").empty());
  Advance(1ms);
  EXPECT_EQ(Frames("0FF#"), std::vector<std::string>{Emcy(0x8130, 0x01, 0x03, 0x80)});
  EXPECT_EQ(Entry(1), 0x80038130u);
  EXPECT_EQ(stack().State(), canopen::NmtState::kPreOperational);
  EXPECT_TRUE(On());
  Send("703#05");
  EXPECT_EQ(Frames("0FF#"), std::vector<std::string>{EmcyReset()});
  EXPECT_EQ(Read(0x1003, 0), 0);
}

// §2.2.14: "A non-zero event timer for an RPDO means that it will result in a network fault being
// flagged if it has not been received within this timeframe while in Operational mode"; Table 9
// 00008100h; 1029h sub 1 (the text's "sub-index 4" is the Output Error entry: README choice 16).
TEST_F(PsFaultTest, RpdoTimeoutIs00008100) {
  Write(0x1400, 5, 100, 2);
  Start();
  Send("27F#FDFF");
  Advance(1ms);
  EXPECT_TRUE(On());
  Frames();
  Advance(98ms);  // 100 ms after the RPDO
  EXPECT_TRUE(Frames("0FF#").empty());
  Advance(1ms);
  EXPECT_EQ(Frames("0FF#"), std::vector<std::string>{Emcy(0x8100, 0x01, 0x00, 0x00)});
  EXPECT_EQ(Entry(1), 0x00008100u);
  EXPECT_EQ(stack().State(), canopen::NmtState::kPreOperational);
  EXPECT_TRUE(On());
}

// Table 9: "00008140h ... Bus OFF Event" (the EMCY column's "8400h" is a slip: README choice 5).
// The EMCY goes out once the controller is back, then the error reset, which removes the entry
// from 1003h (§2.2.4: "immediately removed when the error condition has been cleared"; sub 0 is zero
// in an error-free state); 1029h sub 1 = 0 → pre-operational.
TEST_F(PsFaultTest, BusOffIs00008140) {
  Start();
  Frames();
  node_port_.SetControllerState({ControllerState::kBusOff, 256, 0});
  EXPECT_EQ(stack().State(), canopen::NmtState::kPreOperational);
  EXPECT_TRUE(Frames("0FF#").empty());
  EXPECT_EQ(od().GetUnsigned(0x1003, 0), 1u);  // no SDO while bus-off: the dictionary itself
  EXPECT_EQ(od().GetUnsigned(0x1003, 1), 0x00008140u);
  node_port_.SetControllerState({ControllerState::kErrorActive, 0, 0});
  Advance(1ms);
  // "Recovered from bus-off": sent, then the error reset at once, and the entry leaves with it.
  EXPECT_EQ(Frames("0FF#"), (std::vector<std::string>{Emcy(0x8140, 0x01, 0x00, 0x00), EmcyReset()}));
  EXPECT_EQ(Read(0x1001, 0), 0);
  EXPECT_EQ(Read(0x1003, 0), 0);
}

}  // namespace
}  // namespace canfleet::devices::test
