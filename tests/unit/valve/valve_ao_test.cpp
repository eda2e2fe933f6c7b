// The analog output block (UMAX020411A §1.5, §3.3.19-3.3.29, §3.4.26-3.4.48): the Figure 11 line
// and the 2342h responses, the fault > override > enable > control order, ramps, 2370h averaging,
// open/short detection, dither, the output types and their 6310h cascade, and the SDO range checks.
#include "tests/unit/valve/valve_fixture.hpp"

namespace canfleet::devices::valve::test {
namespace {

constexpr std::uint32_t kInvalid = 0x06090030;
constexpr std::uint32_t kTooHigh = 0x06090031;
constexpr std::uint32_t kTooLow = 0x06090032;

class ValveAoTest : public ValveTest {
 protected:
  /// RPDO1 (205h): 7300h.1-4.
  void Rpdo1(std::int16_t a, std::int16_t b = 0, std::int16_t c = 0, std::int16_t d = 0) {
    Send("205#" + LeHex(static_cast<std::uint16_t>(a), 2) + LeHex(static_cast<std::uint16_t>(b), 2) +
         LeHex(static_cast<std::uint16_t>(c), 2) + LeHex(static_cast<std::uint16_t>(d), 2));
  }
  void NoRamps(std::uint8_t sub) {
    Write(0x2330, sub, 0, 2);
    Write(0x2331, sub, 0, 2);
  }
  std::int64_t Fv(std::uint8_t sub) { return Read(0x7330, sub, true); }
  void Operational() {
    SilenceTpdos();
    Start();
    Frames();
  }
};

// §1.5 Figure 11 with the default response 1 "Output OFF below Scaling 1 PV" (Table 18): the
// factory line 300..1500 PV -> 300..1500 mA.
TEST_F(ValveAoTest, RpdoDrivesTheCurrentThroughTheLine) {
  NoRamps(1);
  Operational();
  Rpdo1(900);
  Advance(2ms);
  EXPECT_EQ(Fv(1), 900);
  EXPECT_EQ(Out("OUT1.current_mA"), 900);
  EXPECT_TRUE(io().Bool("OUT1.on"));
  Rpdo1(200);  // below 7320h: off
  Advance(2ms);
  EXPECT_EQ(Fv(1), 0);
  EXPECT_FALSE(io().Bool("OUT1.on"));
  Rpdo1(2000);  // above 7322h: held at 7323h
  Advance(2ms);
  EXPECT_EQ(Fv(1), 1500);
}

// Table 18, 0 "single output profile": held at S1FV below S1PV; 2 "OFF above Scaling 2 PV".
TEST_F(ValveAoTest, ControlResponses) {
  NoRamps(1);
  Write(0x2342, 1, 0, 1);
  Operational();
  Rpdo1(100);
  Advance(2ms);
  EXPECT_EQ(Fv(1), 300);
  Write(0x2342, 1, 2, 1);
  Rpdo1(1600);
  Advance(2ms);
  EXPECT_EQ(Fv(1), 0);
  Rpdo1(1500);
  Advance(2ms);
  EXPECT_EQ(Fv(1), 1500);
}

// §3.3.25: "7321h higher than 7323h for an inverse response".
TEST_F(ValveAoTest, InverseLine) {
  NoRamps(1);
  Write(0x7321, 1, 1500, 2);
  Write(0x7323, 1, 300, 2);
  Operational();
  Rpdo1(300);
  Advance(2ms);
  EXPECT_EQ(Fv(1), 1500);
  Rpdo1(1200);
  Advance(2ms);
  EXPECT_EQ(Fv(1), 600);
}

// §3.4.32/3.4.33: 2330h/2331h are the ms from S1FV to S2FV (1200 mA in 1000 ms = 1.2 mA/ms); the
// node runs every millisecond while the ramp moves and sleeps once it arrived.
TEST_F(ValveAoTest, RampsUpAndDown) {
  Operational();
  Rpdo1(1500);
  Advance(501ms);  // 500 one-millisecond steps after the run that saw the RPDO
  EXPECT_NEAR(static_cast<double>(Fv(1)), 600, 2);
  Advance(800ms);
  EXPECT_EQ(Fv(1), 1500);
  Write(0x2331, 1, 2000, 2);  // 0.6 mA/ms down
  Rpdo1(900);
  Advance(501ms);
  EXPECT_NEAR(static_cast<double>(Fv(1)), 1200, 2);
  Advance(600ms);
  EXPECT_EQ(Fv(1), 900);
  Advance(300ms);
  EXPECT_TRUE(valve().Idle());
}

// §1.4 a-c / §1.5: override (2360h-2362h) beats enable (2350h-2352h) beats control; a faulted input
// beats all of them (6340h 1: 7341h).
TEST_F(ValveAoTest, FaultOverOverrideOverEnableOverControl) {
  NoRamps(1);
  Write(0x2360, 1, 2, 1);  // override: input DI1 (sub 8), Table 20 0 = when ON
  Write(0x2361, 1, 8, 1);
  Write(0x2350, 1, 2, 1);  // enable: input DI2 (sub 9), Table 19 0 = enable when ON, else shut off
  Write(0x2351, 1, 9, 1);
  Write(0x2352, 1, 0, 1);
  Operational();
  Rpdo1(900);
  Advance(2ms);
  EXPECT_EQ(Fv(1), 0);  // DI2 OFF: disabled
  SetEnum("IN9.level", "high");
  Advance(2ms);
  EXPECT_EQ(Fv(1), 900);  // enabled: the control
  SetEnum("IN8.level", "high");
  SetEnum("IN9.level", "low");
  Advance(2ms);
  EXPECT_EQ(Fv(1), 750);  // override (2300h) while disabled
  // Control from UI1 (7120h..7122h = 500..4500 mV) and UI1 out of span at once (2112h = 0).
  Write(0x7322, 1, 4500, 2);
  Write(0x7320, 1, 500, 2);
  Write(0x2340, 1, 2, 1);
  Write(0x2341, 1, 1, 1);
  Write(0x2112, 1, 0, 2);
  SetNumber("IN1.voltage_mV", 100);
  Advance(2ms);
  EXPECT_EQ(Fv(1), 500);  // 7341h
  SetNumber("IN1.voltage_mV", 2500);
  SetEnum("IN8.level", "low");
  SetEnum("IN9.level", "high");
  Advance(2ms);
  EXPECT_EQ(Fv(1), 900);  // 300 + 2000 x 1200 / 4000
}

// Table 21, 0 "maintain last state".
TEST_F(ValveAoTest, FaultModeHoldsTheLastValue) {
  NoRamps(1);  // (control from UI1 below)
  Write(0x7322, 1, 4500, 2);
  Write(0x7320, 1, 500, 2);
  Write(0x2340, 1, 2, 1);
  Write(0x2341, 1, 1, 1);
  Write(0x2112, 1, 0, 2);
  Write(0x6340, 1, 0, 1);
  SetNumber("IN1.voltage_mV", 3500);
  Advance(2ms);
  EXPECT_EQ(Fv(1), 1200);
  SetNumber("IN1.voltage_mV", 6000);  // above 7149h: faulted
  Advance(2ms);
  EXPECT_EQ(Fv(1), 1200);
}

// Table 19, 1 "enable when ON, else ramp OFF" and 2 "... else keep last value".
TEST_F(ValveAoTest, EnableRampOffAndKeepLast) {
  Write(0x2350, 2, 2, 1);
  Write(0x2351, 2, 8, 1);  // DI1
  Write(0x2352, 2, 1, 1);
  SetEnum("IN8.level", "high");
  Operational();
  Rpdo1(0, 1500);
  Advance(1300ms);
  EXPECT_EQ(Fv(2), 1500);
  SetEnum("IN8.level", "low");
  Advance(501ms);
  EXPECT_NEAR(static_cast<double>(Fv(2)), 900, 2);  // ramping down to 0 at 1.2 mA/ms
  Write(0x2352, 2, 2, 1);
  Advance(100ms);
  const auto held = Fv(2);
  Advance(100ms);
  EXPECT_EQ(Fv(2), held);
}

// §3.4.43/3.4.44: 2370h is the measured current averaged over 2371h 1 ms samples: it changes once
// per window; 2371h = 1 follows at once.
TEST_F(ValveAoTest, FeedbackIsAveragedOver2371hSamples) {
  NoRamps(1);
  Operational();
  Advance(200ms);
  Rpdo1(1000);
  Advance(2ms);
  EXPECT_EQ(Fv(1), 1000);
  EXPECT_EQ(Read(0x2370, 1, true), 0);
  Advance(250ms);
  EXPECT_EQ(Read(0x2370, 1, true), 1000);
  Write(0x2371, 1, 1, 2);
  Rpdo1(700);
  Advance(2ms);
  EXPECT_EQ(Read(0x2370, 1, true), 700);
}

// §1.5, §3.4.27-3.4.29, Table 33: |7330h - 2370h| > 2311h (an open load reads 0 mA) for 2312h
// -> 1001F002h, EMCY F002h; it clears once the feedback is back within 2311h.
TEST_F(ValveAoTest, OpenCircuitAfterItsDelay) {
  NoRamps(1);
  Operational();
  Rpdo1(900);
  Advance(300ms);
  SetEnum("OUT1.load", "open");
  Advance(999ms);
  EXPECT_TRUE(Frames("085#").empty());
  Advance(150ms);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{Emcy(0xF002, 0x01, 1, 0x10)});
  EXPECT_EQ(Read(0x1003, 1), 0x1001F002);
  EXPECT_EQ(Out("OUT1.current_mA"), 0);
  SetEnum("OUT1.load", "nominal");
  Advance(250ms);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{EmcyReset()});
  EXPECT_EQ(Read(0x1003, 0), 0);
}

// §1.5: "when the output is commanded off, the flags are automatically reset"; 2310h FALSE
// disables the check.
TEST_F(ValveAoTest, OpenLoadOffOrUncheckedIsNoFault) {
  NoRamps(2);
  Write(0x2310, 2, 0, 1);
  SetEnum("OUT1.load", "open");
  SetEnum("OUT2.load", "open");
  Operational();
  Rpdo1(0, 900);
  Advance(3s);
  EXPECT_TRUE(Frames("085#").empty());
}

// §1.5 + §3.2.13: an output fault applies 1029h sub 5 (here 2 = stopped), and a stopped node
// drives nothing (README).
TEST_F(ValveAoTest, OutputFaultAppliesErrorBehaviourSub5) {
  NoRamps(3);
  Write(0x1029, 5, 2, 1);
  Write(0x2312, 3, 0, 2);
  Write(0x2371, 3, 1, 2);
  Operational();
  Rpdo1(0, 0, 800);
  Advance(5ms);
  SetEnum("OUT3.load", "short");
  Advance(3ms);
  EXPECT_EQ(stack().State(), canopen::NmtState::kStopped);
  EXPECT_EQ(Value(0x7330, 3), 0);
}

// §1.5, §3.4.31: dither (2320h/2321h, global) rides on a driven current output.
TEST_F(ValveAoTest, DitherOnCurrentOutputs) {
  NoRamps(1);
  Write(0x2321, 1, 120, 2);
  Operational();
  Rpdo1(800);
  Advance(2ms);
  EXPECT_EQ(Out("OUT1.dither_mA"), 120);
  EXPECT_EQ(Out("OUT1.dither_Hz"), 250);
  EXPECT_EQ(Out("OUT2.dither_mA"), 0);
}

// Table 14 and §1.5 "all objects related to the output ... are automatically updated": digital,
// PWM (0.1 %) and back to current (the factory values).
TEST_F(ValveAoTest, OutputTypeCascade) {
  Write(0x6310, 2, 1000, 2);
  EXPECT_EQ(Read(0x7320, 2, true), 0);
  EXPECT_EQ(Read(0x7322, 2, true), 1);
  EXPECT_EQ(Read(0x7323, 2, true), 1);
  EXPECT_EQ(Read(0x6302, 2), 0);
  EXPECT_EQ(Read(0x7341, 2, true), 1);
  EXPECT_EQ(Read(0x2300, 2, true), 1);
  Write(0x6310, 2, 40, 2);
  EXPECT_EQ(Read(0x7321, 2, true), 100);
  EXPECT_EQ(Read(0x7323, 2, true), 900);
  EXPECT_EQ(Read(0x6332, 2), 1);
  Write(0x6310, 2, 20, 2);
  EXPECT_EQ(Read(0x7320, 2, true), 300);
  EXPECT_EQ(Read(0x7323, 2, true), 1500);
  EXPECT_EQ(Read(0x6302, 2), 3);
  EXPECT_EQ(Read(0x7341, 2, true), 500);
  EXPECT_EQ(Read(0x2300, 2, true), 750);
}

// Table 14 voltage (PWM-averaged up to the supply) and PWM (duty in 0.1 %).
TEST_F(ValveAoTest, VoltageAndPwmOutputs) {
  Write(0x6310, 3, 10, 2);
  Write(0x6310, 4, 40, 2);
  NoRamps(3);
  NoRamps(4);
  Operational();
  Rpdo1(0, 0, 12000, 500);
  Advance(2ms);
  EXPECT_EQ(Fv(3), 12000);
  EXPECT_EQ(Out("OUT3.voltage_mV"), 12000);
  EXPECT_EQ(Out("OUT3.duty_pct"), 50);
  EXPECT_EQ(Fv(4), 500);
  EXPECT_EQ(Out("OUT4.duty_pct"), 50);
  EXPECT_EQ(Out("OUT4.voltage_mV"), 12000);
}

// Which values an output accepts (Table 14, §3.3.24-3.3.29, §3.4.20/21/28).
TEST_F(ValveAoTest, RangeChecks) {
  Refused(0x6310, 1, 30, 2, kInvalid);
  Refused(0x6310, 9, 20, 2, kInvalid);  // DO1-4: only 0 or 1000 (§1.4)
  Refused(0x6310, 10, 1020, 2, kInvalid);
  Refused(0x7320, 1, 1500, 2, kTooHigh);  // must stay below 7322h
  Refused(0x7322, 1, 300, 2, kTooLow);
  Refused(0x7321, 1, 2501, 2, kTooHigh);  // Imax 2.5 A
  Refused(0x7341, 1, static_cast<std::uint16_t>(-1), 2, kTooLow);
  Refused(0x2311, 1, 151, 2, kTooHigh);   // 10 % of 1500
  Refused(0x2220, 1, 400, 2, kTooLow);    // below the hold current
  Refused(0x2221, 1, 2100, 2, kTooHigh);  // above the hotshot current
  Refused(0x2341, 1, 25, 1, kTooHigh);    // EDS limit: Table 16 ends at 24
  Write(0x2340, 1, 2, 1);
  Refused(0x2341, 1, 13, 1, kTooHigh);  // analog inputs are 1..12
  Refused(0x2341, 1, 0, 1, kTooLow);
  Write(0x2341, 1, 12, 1);
  Write(0x2340, 1, 10, 1);  // power supply: "N/A" number
  Write(0x2341, 1, 0, 1);
}

// Table 20, 1 "override when OFF": the override FV applies while the input is OFF.
TEST_F(ValveAoTest, OverrideWhenOff) {
  NoRamps(1);
  Write(0x2360, 1, 2, 1);
  Write(0x2361, 1, 12, 1);  // DI5
  Write(0x2362, 1, 1, 1);
  Write(0x2300, 1, 1200, 2);
  Operational();
  Rpdo1(900);
  Advance(2ms);
  EXPECT_EQ(Fv(1), 1200);
  SetEnum("IN12.level", "high");
  Advance(2ms);
  EXPECT_EQ(Fv(1), 900);
}

// Choice (README): a stopped node drives nothing; pre-operational keeps the application running.
TEST_F(ValveAoTest, StoppedNodeDrivesNothing) {
  NoRamps(1);
  Operational();
  Rpdo1(900);
  Advance(2ms);
  Send("000#0205");
  Advance(2ms);
  EXPECT_EQ(Value(0x7330, 1), 0);  // no SDO in stopped
  EXPECT_FALSE(io().Bool("OUT1.on"));
  Send("000#8005");
  Advance(2ms);
  EXPECT_EQ(Fv(1), 900);
}

}  // namespace
}  // namespace canfleet::devices::valve::test
