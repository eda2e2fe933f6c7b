// The programmable blocks wired through their objects (UMAX020411A §1.5 Tables 15-17, §1.6 PID,
// §1.7 lookup tables, §1.8 logic, §1.9 math): the algorithms are the shared library's (tested in
// tests/unit/blocks); these tests prove the valve's objects, numbering and scaling reach them.
#include "tests/unit/valve/valve_fixture.hpp"

namespace canfleet::devices::valve::test {
namespace {

constexpr std::uint32_t kTooHigh = 0x06090031;
constexpr std::uint32_t kTooLow = 0x06090032;

class ValveBlocksTest : public ValveTest {
 protected:
  /// 2500h.n: the extra received PVs (CANopen message 13-24), 0..1000 = 0..100.0 by default.
  void Extra(std::uint8_t n, std::int16_t value) {
    Write(0x2500, n, static_cast<std::uint16_t>(value), 2);
    Advance(3ms);
  }
};

// §1.7.1, §1.7.3: data response; X from CANopen message 13 (2500h.1); the default 0..100 line,
// then "jump to" and "ignore".
TEST_F(ValveBlocksTest, LookupTableDataResponse) {
  Write(0x3010, 0, 1, 1);
  Write(0x3011, 0, 13, 1);
  Extra(1, 55);
  EXPECT_EQ(Read(0x3018, 0, true), 55);
  Write(0x3015, 7, 2, 1);  // point 7 (X = 60) jump to
  Advance(2ms);
  EXPECT_EQ(Read(0x3018, 0, true), 60);
  Write(0x3015, 5, 0, 1);  // ignore from point 5: above X4 the output is Y4
  Advance(2ms);
  EXPECT_EQ(Read(0x3018, 0, true), 30);
}

// §1.7.1 / §3.4.68: X1 <= X2 <= ... <= X11 (write X11 first when widening).
TEST_F(ValveBlocksTest, LookupTableXAxisMustNotDecrease) {
  Refused(0x3016, 11, 85, 4, kTooLow);
  Refused(0x3016, 1, 20, 4, kTooHigh);
  Refused(0x3016, 11, 40000, 4, kTooHigh);  // MaxInt16 in a data response
  Write(0x3016, 11, 4500, 4);
  Write(0x3016, 10, 90, 4);
}

// §1.7.4: time response; point 1 is (0 ms, 0), the others are the interval to the previous point
// (README); OFF = output 0; ON starts at point 1; the end holds.
TEST_F(ValveBlocksTest, LookupTableTimeResponse) {
  Write(0x3025, 1, 1, 1);  // LT02 time response
  EXPECT_EQ(Read(0x3026, 1, true), 0);
  for (std::uint8_t k = 2; k <= 11; ++k)
    Write(0x3026, k, 100, 4);          // 100 ms per point
  Refused(0x3026, 1, 5, 4, kTooHigh);  // point 1 stays at 0 ms
  Refused(0x3026, 2, 0, 4, kTooLow);   // at least 1 ms
  Write(0x3020, 0, 3, 1);              // X source: constant 2 = TRUE
  Write(0x3021, 0, 2, 1);
  Advance(251ms);
  EXPECT_EQ(Read(0x3028, 0, true), 25);
  Advance(1000ms);
  EXPECT_EQ(Read(0x3028, 0, true), 100);
  EXPECT_TRUE(valve().Idle());  // holding the end: nothing to run
  Write(0x3021, 0, 1, 1);       // constant 1 = FALSE
  Advance(2ms);
  EXPECT_EQ(Read(0x3028, 0, true), 0);
}

// §1.7.4: with auto-repeat the profile starts over at its end.
TEST_F(ValveBlocksTest, LookupTableAutoRepeat) {
  Write(0x3035, 1, 1, 1);
  for (std::uint8_t k = 2; k <= 11; ++k)
    Write(0x3036, k, 10, 4);  // 100 ms in all
  Write(0x3032, 0, 1, 1);
  Write(0x3030, 0, 3, 1);
  Write(0x3031, 0, 2, 1);
  Advance(151ms);
  EXPECT_EQ(Read(0x3038, 0, true), 50);
}

// §1.8: LB1 selects table A (LT01) while its conditions hold, else B, else C (default, LT03);
// 3310h names the table, 3320h gives its output as 0.1 % of its Y range (Table 17).
TEST_F(ValveBlocksTest, LogicBlockSelectsTables) {
  Write(0x3010, 0, 1, 1);  // LT01: X = 2500h.1
  Write(0x3011, 0, 13, 1);
  Write(0x3030, 0, 1, 1);  // LT03: X = 2500h.2
  Write(0x3031, 0, 14, 1);
  // Function A, condition 1: 2500h.1 > constant 9 (5.0); conditions 2 and 3 not used (N/A = true
  // for "Cnd1 And Cnd2 And Cnd3", Table 28).
  Write(0x3411, 4, 9, 1);
  Write(0x3411, 5, 2, 1);
  Write(0x3412, 1, 0, 1);
  Write(0x3413, 1, 0, 1);
  Write(0x3300, 1, 1, 1);
  Extra(2, 20);
  Extra(1, 55);
  EXPECT_EQ(Read(0x3310, 1), 1);
  EXPECT_EQ(Read(0x3320, 1, true), 550);
  Extra(1, 4);  // A false; B's factory conditions (2500h.1 == 3.14) false; C = default
  EXPECT_EQ(Read(0x3310, 1), 3);
  EXPECT_EQ(Read(0x3320, 1, true), 200);
  Write(0x3300, 1, 0, 1);
  Advance(2ms);
  EXPECT_EQ(Read(0x3310, 1), 0);
}

// §1.9's own example: a joystick (input 1, gain 0.75) plus a potentiometer (input 2, gain 0.25)
// gives 0..100 %: 100 % x 0.75 + 50 % x 0.25 = 87.5 % -> 4030h 8750 (0..10000, 2 digits).
TEST_F(ValveBlocksTest, MathJoystickPlusPotentiometer) {
  Write(0x4100, 1, 1, 1);
  Write(0x4101, 1, 13, 1);
  Write(0x4100, 2, 1, 1);
  Write(0x4101, 2, 14, 1);
  Write(0x4140, 1, 75, 1);
  Write(0x4140, 2, 25, 1);
  Write(0x4000, 1, 1, 1);
  Extra(1, 1000);
  Extra(2, 500);
  EXPECT_EQ(Read(0x4030, 1, true), 8750);
  Write(0x4150, 1, 2, 1);  // ">" gives 0 or 1: 0.75 > 0.125
  Advance(2ms);
  EXPECT_EQ(Read(0x4030, 1, true), 10000);
  Write(0x4000, 1, 0, 1);  // disabled: 0
  Advance(2ms);
  EXPECT_EQ(Read(0x4030, 1, true), 0);
}

// §1.6 Figure 14 with G = 1.0, Ki = Kd = 0: the output is the error in %, every 7456h (10 ms):
// target 60 % (2500h.1 = 600), feedback 20 % -> 2460h = 400 (40.0 %). It drives OUT1 through
// 7320h/7322h = 0/1000 (Table 17 "PID 0 % / 100 %, 1 digit").
TEST_F(ValveBlocksTest, PidOnObjectsDrivesAnOutput) {
  Write(0x7450, 1, 10, 2);
  Write(0x2451, 1, 0, 2);
  Write(0x2452, 1, 0, 2);
  Write(0x2453, 1, 1, 1);
  Write(0x2454, 1, 13, 1);
  Write(0x2455, 1, 1, 1);
  Write(0x2456, 1, 14, 1);
  Write(0x2500, 1, 600, 2);
  Write(0x2500, 2, 200, 2);
  Write(0x2330, 1, 0, 2);
  Write(0x7322, 1, 1000, 2);
  Write(0x7320, 1, 0, 2);
  Write(0x2340, 1, 4, 1);
  Write(0x2341, 1, 1, 1);
  Advance(30ms);
  EXPECT_EQ(Read(0x2460, 1, true), 400);
  EXPECT_EQ(Read(0x7330, 1, true), 780);  // 300 + 400 x 1200 / 1000
  Write(0x2500, 2, 595, 2);               // |E| = 0.5 % < 2450h 1.0 %: treated as 0
  Advance(30ms);
  EXPECT_EQ(Read(0x2460, 1, true), 0);
}

// §1.6: "Unless both the target and feedback inputs have legitimate control sources selected, the
// PID loop is disabled": output 0 and no cycle runs.
TEST_F(ValveBlocksTest, PidWithoutFeedbackIsDisabled) {
  Write(0x2453, 2, 3, 1);
  Write(0x2454, 2, 15, 1);
  Advance(100ms);
  EXPECT_EQ(Read(0x2460, 2, true), 0);
  EXPECT_TRUE(valve().Idle());
}

// Table 15/16 through an output: the output commanded FV of OUT1 (source 8) feeds math 2, which
// reads it one run later (a later block, README "evaluation order").
TEST_F(ValveBlocksTest, OutputFeedbackAsSource) {
  Write(0x2330, 1, 0, 2);
  Write(0x4200, 1, 8, 1);
  Write(0x4201, 1, 1, 1);
  Write(0x4203, 1, 3, 1);  // Table 17: 7330h is read with 6302h = 3 digits (1500 mA = 1.500)
  Write(0x4220, 1, 0, 2);
  Write(0x4222, 1, 1500, 2);
  Write(0x4200, 2, 3, 1);  // + constant FALSE (0)
  Write(0x4201, 2, 1, 1);
  Write(0x4000, 2, 1, 1);
  SilenceTpdos();
  Start();
  Send("205#DC05000000000000");  // 7300h.1 = 1500
  Advance(5ms);
  EXPECT_EQ(Read(0x4030, 2, true), 10000);
}

}  // namespace
}  // namespace canfleet::devices::valve::test
