// The two valve drives of the AX023241 on their objects (1.4, Tables 8-12, 1.5, C3-1.3.17-1.3.31,
// C3-1.4.7-1.4.23): the default RPDO control with ramps, NMT gating, override and enable sources,
// control fault responses, the output types, load faults with EMCY/1003h/1029h.
#include "tests/unit/encoder/encoder_fixture.hpp"

namespace canfleet::devices::encoder::test {
namespace {

class OutputTest : public EncoderTest {
 protected:
  void NoRamps(std::uint8_t n) {
    Write(0x2330, n, 0, 2);
    Write(0x2331, n, 0, 2);
  }
  /// RPDO1: 7300h.1 and 7300h.2 (C3-1.2.16).
  void Rpdo1(std::int16_t pv1, std::int16_t pv2) {
    Send("205#" + LeHex(static_cast<std::uint16_t>(pv1), 2) + LeHex(static_cast<std::uint16_t>(pv2), 2));
  }
};

// C3-1.2.12/1.2.16, 1.4: by default output n follows "Received CAN Message" n = 7300h.n (RPDO1),
// PV 0..5000 onto FV 0..5000 mA (7320h-7323h), held at 2500 mA (Table 8); ramp up 1000 ms for the
// 5000 mA range = 5 mA per ms (2330h).
TEST_F(OutputTest, RpdoControlsTheCurrentThroughTheRamp) {
  SilenceTpdo1();
  Start();
  Rpdo1(1000, 0);
  Advance(1ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 5);
  Advance(99ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 500);
  Advance(100ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 1000);
  EXPECT_TRUE(On("OUT1.on"));
  EXPECT_DOUBLE_EQ(Out("OUT1.voltage_mV"), 8000);  // 1 A x 8 ohm
  EXPECT_EQ(Out("OUT1.frequency_Hz"), 25000);
  EXPECT_EQ(Read(0x7330, 1, true), 1000);
  EXPECT_EQ(Read(0x2370, 1, true), 1000);
  EXPECT_FALSE(device().Ticking());
  Rpdo1(9000, 0);
  Advance(400ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 2500);
  EXPECT_EQ(Read(0x7330, 1, true), 2500);
}

// README "Outputs" (the family's Quad §4.2): a CAN controlled output drives only in operational.
TEST_F(OutputTest, CanControlledOutputsAreOffOutsideOperational) {
  NoRamps(1);
  Write(0x7300, 1, 800, 2);
  Advance(5ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 0);
  Start();
  Advance(1ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 800);
  Send("000#8005");  // enter pre-operational
  Advance(1ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 0);
  Send("000#0105");
  Advance(1ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 800);
  Send("000#0205");  // stopped
  Advance(1ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 0);
}

// Table 11: the override input (here the constant TRUE, 5010h.2, source 9 number 2) drives 2300h
// regardless of the control; 2362h = 1 overrides when the input is Off instead.
TEST_F(OutputTest, OverrideDrivesTheOverrideValue) {
  NoRamps(1);
  Start();
  Rpdo1(1000, 0);
  Write(0x2300, 1, 700, 2);
  Write(0x2361, 1, 2, 1);
  Write(0x2360, 1, 9, 1);
  Advance(1ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 700);
  EXPECT_EQ(Read(0x7330, 1, true), 700);
  Write(0x2362, 1, 1, 1);
  Advance(1ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 1000);
}

// Table 10 option 0 "Enable When On, Else Shutoff": enable = constant FALSE (5010h.1) shuts off.
TEST_F(OutputTest, EnableInputOffShutsTheOutputOff) {
  Start();
  Rpdo1(1000, 0);
  Advance(300ms);
  ASSERT_EQ(Out("OUT1.current_mA"), 1000);
  Write(0x2351, 1, 1, 1);
  Write(0x2350, 1, 9, 1);
  Advance(1ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 0);  // no ramp: a shutoff
  Write(0x2351, 1, 2, 1);
  Advance(1ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 5);  // ramps up again
}

// 1.4 Table 12 through 6340h: a fault on the control input (input 1, out of span) shuts off (0),
// applies 7341h (1: 500 mA) or holds the last value (2).
TEST_F(OutputTest, ControlFaultResponseOnAFaultedInput) {
  Write(0x6110, 1, 60, 2);  // frequency 0.5-50 Hz: 7120h..7122h = 50..5000
  Write(0x2112, 1, 0, 2);
  Write(0x2110, 1, 1, 1);
  NoRamps(1);
  Write(0x2340, 1, 2, 1);  // control: quadrature/pulse input 1
  Write(0x7323, 1, 2000, 2);
  SetNumber("IN1.frequency_Hz", 25.25);  // 2525 of 50..5000: 50 %
  Advance(1ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 1000);
  SetNumber("IN1.frequency_Hz", 0.1);
  Advance(1ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 0);
  Write(0x6340, 1, 1, 1);
  Advance(1ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 500);
  SetNumber("IN1.frequency_Hz", 25.25);
  Advance(1ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 1000);
  Write(0x6340, 1, 2, 1);
  SetNumber("IN1.frequency_Hz", 0.1);
  Advance(1ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 1000);
  EXPECT_EQ(TryWrite(0x6340, 1, 3, 1), SdoAborted(0x6340, 1, 0x06090031));
}

// Table 8 / 1.4: 6310h = 10 (voltage, 0.1 V): its objects follow the type (6332h = 1, 7323h = 600);
// the output switches Vps to the commanded mean.
TEST_F(OutputTest, VoltageOutput) {
  Write(0x6310, 1, 10, 2);
  EXPECT_EQ(Read(0x6332, 1), 1);
  EXPECT_EQ(Read(0x7323, 1, true), 600);
  EXPECT_EQ(Read(0x7322, 1, true), 600);
  EXPECT_EQ(Read(0x7341, 1, true), 0);
  NoRamps(1);
  Start();
  Rpdo1(120, 0);  // 12.0 V
  Advance(1ms);
  EXPECT_DOUBLE_EQ(Out("OUT1.voltage_mV"), 12000);
  EXPECT_DOUBLE_EQ(Out("OUT1.current_mA"), 1500.0);
  EXPECT_DOUBLE_EQ(Out("OUT1.duty_pct"), 50.0);
  EXPECT_EQ(Read(0x7330, 1, true), 120);
  EXPECT_EQ(TryWrite(0x6310, 1, 30, 2), SdoAborted(0x6310, 1, 0x06090030));
}

// Table 8 PWM (0.1 %) at 2380h kHz; 4.3: "Configurable frequency ONLY if no current output types
// are used, otherwise default 25kHz is used".
TEST_F(OutputTest, PwmOutputFrequency) {
  Write(0x6310, 1, 40, 2);
  Write(0x2380, 1, 2, 2);
  NoRamps(1);
  Start();
  Rpdo1(250, 0);
  Advance(1ms);
  EXPECT_DOUBLE_EQ(Out("OUT1.duty_pct"), 25.0);
  EXPECT_EQ(Out("OUT1.frequency_Hz"), 25000);  // output 2 is a current output
  Write(0x6310, 2, 40, 2);
  Advance(1ms);
  EXPECT_EQ(Out("OUT1.frequency_Hz"), 2000);
  EXPECT_DOUBLE_EQ(Out("OUT1.voltage_mV"), 6000);
}

// Figure 5: a hotshot output drives 2000 mA for 1000 ms, then holds 500 mA; the device sleeps
// through the hotshot phase.
TEST_F(OutputTest, HotshotOutput) {
  Write(0x6310, 2, 1020, 2);
  Start();
  Rpdo1(0, 1);
  Advance(1ms);
  EXPECT_EQ(Out("OUT2.current_mA"), 2000);
  EXPECT_TRUE(On("OUT2.hotshot"));
  const auto evaluations = device().Evaluations();
  Advance(999ms);
  EXPECT_EQ(Out("OUT2.current_mA"), 2000);
  EXPECT_LE(device().Evaluations() - evaluations, 1u);
  Advance(1ms);
  EXPECT_EQ(Out("OUT2.current_mA"), 500);
  EXPECT_FALSE(On("OUT2.hotshot"));
}

// 1.5 / 4.3: a dead short trips the driver; after 2312h ms EMCY F002h, 1003h 20nnF002h; the driver
// is retried every second and resumes without the short (error reset).
TEST_F(OutputTest, ShortCircuitTripsRetriesAndReports) {
  NoRamps(1);
  Start();
  Rpdo1(1000, 0);
  Advance(1ms);
  ASSERT_EQ(Out("OUT1.current_mA"), 1000);
  SetEnum("OUT1.load", "short");
  Advance(1ms);
  EXPECT_TRUE(On("OUT1.tripped"));
  EXPECT_FALSE(On("OUT1.on"));
  EXPECT_EQ(Read(0x2370, 1, true), 0);
  Advance(999ms);
  EXPECT_TRUE(Frames("085#").empty());
  Advance(1ms);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{Emcy(0xF002, 1, 0x20)});
  EXPECT_EQ(Read(0x1003, 1), 0x2001F002);
  EXPECT_EQ(stack().State(), canopen::NmtState::kOperational);  // 1029h sub 5 default: no change
  SetEnum("OUT1.load", "nominal");
  Advance(500ms);
  EXPECT_TRUE(On("OUT1.tripped"));  // waits for the next retry
  Advance(500ms);
  EXPECT_FALSE(On("OUT1.tripped"));
  EXPECT_EQ(Out("OUT1.current_mA"), 1000);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{"085#0000000000000000"});
}

// An output fault of a proportional type applies 1029h sub 5 (0 = pre-operational); the CAN
// controlled output is then off, so the short is no longer seen and the error ends.
TEST_F(OutputTest, ShortCircuitAppliesTheAnalogOutputBehaviour) {
  Write(0x1029, 5, 0, 1);
  Write(0x2312, 1, 0, 2);
  NoRamps(1);
  Start();
  Rpdo1(1000, 0);
  Advance(1ms);
  SetEnum("OUT1.load", "short");
  Advance(1ms);
  EXPECT_EQ(stack().State(), canopen::NmtState::kPreOperational);
  Advance(1ms);
  EXPECT_EQ(Frames("085#"), (std::vector<std::string>{Emcy(0xF002, 1, 0x20), "085#0000000000000000"}));
  EXPECT_FALSE(On("OUT1.tripped"));
  EXPECT_EQ(Read(0x1003, 0), 0);
}

// 1.5: "In the case of an open circuit, there will be no interruption of the control"; the current
// feedback is below the command by more than 2311h -> after 2312h EMCY F002h, 1003h 10nnF002h.
TEST_F(OutputTest, OpenLoadKeepsDrivingAndReports) {
  NoRamps(2);
  Start();
  Rpdo1(0, 1200);
  Advance(1ms);
  SetEnum("OUT2.load", "open");
  Advance(1ms);
  EXPECT_TRUE(On("OUT2.on"));
  EXPECT_EQ(Out("OUT2.current_mA"), 0);
  Advance(1000ms);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{Emcy(0xF002, 2, 0x10)});
  EXPECT_EQ(Read(0x1003, 1), 0x1002F002);
  Write(0x2310, 2, 0, 1);  // error detection off: the error ends
  Advance(1ms);
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{"085#0000000000000000"});
}

// Table 8 digital on/off: a coil drawing more than 4 A trips (4.3); the fault applies 1029h sub 4.
TEST_F(OutputTest, DigitalOutputOverCurrentIsADigitalOutputFault) {
  Write(0x6310, 1, 1000, 2);
  Write(0x2312, 1, 0, 2);
  Write(0x1029, 4, 2, 1);
  Start();
  Rpdo1(1, 0);
  Advance(1ms);
  EXPECT_TRUE(On("OUT1.on"));
  EXPECT_DOUBLE_EQ(Out("OUT1.current_mA"), 3000.0);
  SetNumber("OUT1.resistance_ohm", 4);
  Advance(1ms);
  EXPECT_TRUE(On("OUT1.tripped"));
  EXPECT_EQ(Frames("085#"), std::vector<std::string>{Emcy(0xF002, 1, 0x20)});
  EXPECT_EQ(stack().State(), canopen::NmtState::kStopped);
}

// 2224h/2225h: the ON edge (2225h = 1) of a digital output waits 2224h ms.
TEST_F(OutputTest, DigitalDelay) {
  Write(0x6310, 1, 1000, 2);
  Write(0x2224, 1, 300, 2);
  Write(0x2225, 1, 1, 1);
  Start();
  Rpdo1(1, 0);
  Advance(299ms);
  EXPECT_FALSE(On("OUT1.on"));
  Advance(2ms);
  EXPECT_TRUE(On("OUT1.on"));
}

// Control source 0: the output follows 7330h as the master writes it (DS-404 field value), in any
// NMT state but stopped; 6310h = 0 disables the output.
TEST_F(OutputTest, ControlSourceZeroFollows7330h) {
  NoRamps(1);
  Write(0x2340, 1, 0, 1);
  Write(0x7330, 1, 800, 2);
  Advance(1ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 800);
  EXPECT_EQ(Read(0x7330, 1, true), 800);
  Write(0x6310, 1, 0, 2);
  Advance(1ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 0);
  EXPECT_FALSE(On("OUT1.on"));
}

// C3-1.3.17/1.3.18: a digital output under control source 0 follows its 6200h bit, XOR 6202h.
TEST_F(OutputTest, DigitalOutputFollows6200hUnderControlSourceZero) {
  Write(0x6310, 2, 1000, 2);
  Write(0x2340, 2, 0, 1);
  Write(0x6200, 1, 0x02, 1);
  Advance(1ms);
  EXPECT_TRUE(On("OUT2.on"));
  Write(0x6202, 1, 0x02, 1);
  Advance(1ms);
  EXPECT_FALSE(On("OUT2.on"));
}

// Table 6/7 as used here (encoder_sources.hpp): received CAN message 8 = 2500h.6 (RPDO3 pre-fills
// 2500h.5/.6, C3-1.2.18), control constant 12 = 5010h.12 (100.0, read as 100 %).
TEST_F(OutputTest, ExtendedSourceNumbersReachEveryReceivedValueAndConstant) {
  Write(0x2330, 1, 0, 2);
  Write(0x2340, 1, 0, 1);
  Write(0x2341, 1, 12, 1);
  Write(0x2340, 1, 9, 1);
  Advance(1ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 2500);
  Write(0x2522, 6, 100, 2);
  Write(0x2500, 6, 20, 2);
  Write(0x2341, 1, 8, 1);
  Write(0x2331, 1, 0, 2);
  Write(0x2340, 1, 1, 1);
  Start();
  Advance(1ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 1000);  // 20 % of 0..5000 mA
}

}  // namespace
}  // namespace canfleet::devices::encoder::test
