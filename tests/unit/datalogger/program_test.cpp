// The data logger's programmable blocks (UMAX181001 §1.4 Tables 13-15, §1.5 lookup tables, §1.6
// logic blocks, §1.7 math blocks, §1.8 received values and constants), wired by (source, number)
// and driven over SDO and RPDO.

#include "node/devices/datalogger_tc_analog/datalogger_objects.hpp"
#include "tests/unit/datalogger/datalogger_fixture.hpp"

namespace canfleet::devices::test {
namespace {

using namespace datalogger;

constexpr std::uint8_t kSourceRpdo = 1;
constexpr std::uint8_t kSourceAi = 2;
constexpr std::uint8_t kSourceConstant = 5;
constexpr std::uint8_t kSourceLut = 6;
constexpr std::uint8_t kSourceMath = 7;
constexpr std::uint8_t kSourceLogic = 8;
constexpr std::uint32_t kValueTooHigh = 0x06090031;
constexpr std::uint32_t kValueTooLow = 0x06090032;

class ProgramTest : public DataLoggerTest {
 protected:
  ProgramTest() {
    ConfigureTcLimitsAway();
    SilenceTpdos();
  }
  void Wire(std::uint16_t source_index, std::uint8_t source_sub, std::uint16_t number_index,
            std::uint8_t number_sub, std::uint8_t source, std::uint8_t number) {
    Write(0, source_index, source_sub, source, 1);
    Write(0, number_index, number_sub, number, 1);
  }
  std::int64_t LutOut(int t) { return Read(0, LutBase(t) + kLutOutput, 0, true); }
  /// RPDO1 (201h + node 5) carries 2500h sub 1-4 (§3.2.14).
  void Rpdo1(std::int16_t a, std::int16_t b = 0, std::int16_t c = 0, std::int16_t d = 0) {
    Send(0, Cob(0x200u + kNode1) + LeHex(static_cast<std::uint16_t>(a), 2) +
                LeHex(static_cast<std::uint16_t>(b), 2) + LeHex(static_cast<std::uint16_t>(c), 2) +
                LeHex(static_cast<std::uint16_t>(d), 2));
  }
};

// §1.5.1-1.5.3: data response, ramp (linear) and jump; X = received PV 1 by RPDO1, which wakes
// the application (no tick runs before).
TEST_F(ProgramTest, LookupTableDataResponseFromAnRpdo) {
  Start(0);
  Wire(LutBase(1) + kLutSource, 0, LutBase(1) + kLutNumber, 0, kSourceRpdo, 1);
  Rpdo1(35);
  Advance(10ms);
  EXPECT_EQ(LutOut(1), 35);                      // default table: Y = X on 0..100
  Write(0, LutBase(1) + kLutResponse, 5, 2, 1);  // point 5 (X 40, Y 40): jump to
  Advance(10ms);
  EXPECT_EQ(LutOut(1), 40);
  Write(0, LutBase(1) + kLutResponse, 4, 0, 1);  // point 4: ignore, so points 4.. are cut
  Rpdo1(70);
  Advance(10ms);
  EXPECT_EQ(LutOut(1), 20);  // "the output ... will be Yn-1"
  // Both ports see the output (3yz8h is shared).
  EXPECT_EQ(Read(1, LutBase(1) + kLutOutput, 0, true), 20);
}

// §1.5.1 and §3.4.37: the X points must not decrease, and stay within the source's scaling
// (AI1: 7120h..7122h = 500..4500 mV).
TEST_F(ProgramTest, LookupTableXAxisRules) {
  const std::uint16_t x = LutBase(2) + kLutX;
  EXPECT_EQ(TryWrite(0, x, 3, 5, 4), SdoAborted(kNode1, x, 3, kValueTooLow));    // < X2 = 10
  EXPECT_EQ(TryWrite(0, x, 3, 35, 4), SdoAborted(kNode1, x, 3, kValueTooHigh));  // > X4 = 30
  Write(0, x, 3, 25, 4);
  Wire(LutBase(2) + kLutSource, 0, LutBase(2) + kLutNumber, 0, kSourceAi, 1);
  EXPECT_EQ(TryWrite(0, x, 11, 5000, 4), SdoAborted(kNode1, x, 11, kValueTooHigh));  // > 7122h
  Write(0, x, 11, 4500, 4);
  // Table 14: AI numbers are 1-10.
  EXPECT_EQ(TryWrite(0, LutBase(2) + kLutNumber, 0, 11, 1),
            SdoAborted(kNode1, LutBase(2) + kLutNumber, 0, kValueTooHigh));
}

// §1.5.4: time response. While the X source is ON the profile plays (X = ms between points),
// holding the last point at its end; OFF gives 0. 3yz3h and point 1 are set to 0 automatically.
TEST_F(ProgramTest, LookupTableTimeResponse) {
  const std::uint16_t base = LutBase(3);
  Write(0, base + kLutResponse, 1, 1, 1);  // time response
  EXPECT_EQ(Read(0, base + kLutXDigits, 0), 0);
  // Points: (0 ms, 0) -> 100 ms ramp to 100 -> 100 ms jump to 50 -> ignore the rest.
  Write(0, base + kLutX, 2, 100, 4);
  Write(0, base + kLutY, 2, 100, 2);
  Write(0, base + kLutX, 3, 100, 4);
  Write(0, base + kLutY, 3, 50, 2);
  Write(0, base + kLutResponse, 3, 2, 1);
  Write(0, base + kLutResponse, 4, 0, 1);
  EXPECT_EQ(TryWrite(0, base + kLutX, 2, 0, 4),
            SdoAborted(kNode1, base + kLutX, 2, kValueTooLow));  // >= 1 ms
  // X source: received PV 2, ON when non-zero.
  Wire(base + kLutSource, 0, base + kLutNumber, 0, kSourceRpdo, 2);
  Write(0, kReceivedPv, 2, 1, 2);
  Advance(10ms);
  EXPECT_EQ(LutOut(3), 0);  // starts at (X1, Y1) on the cycle that sees ON
  Advance(50ms);
  EXPECT_EQ(LutOut(3), 50);  // half-way up the ramp
  Advance(50ms);
  EXPECT_EQ(LutOut(3), 100);
  Advance(100ms);
  EXPECT_EQ(LutOut(3), 50);  // "jump to" 50 for the second interval, then holds at its end
  const auto cycles = logger().Cycles();
  Advance(10s);
  EXPECT_EQ(LutOut(3), 50);
  EXPECT_EQ(logger().Cycles(), cycles);  // holding: no cycles (time is events)
  Write(0, kReceivedPv, 2, 0, 2);
  Advance(10ms);
  EXPECT_EQ(LutOut(3), 0);
}

// §1.6: a logic block selects table A, B or C by its conditions and outputs the selected table
// as 0.1 % of its Y range (3310h, 3320h). LB1 tables 1/2/3 (Table 22); A: received PV 1 > constant
// 5010h sub 10 (10.0); B: default table (operator 0).
TEST_F(ProgramTest, LogicBlockSelectsATable) {
  // Tables 1 and 2 read received PV 3; table 2 is inverted (Y 100..0).
  for (int t : {1, 2})
    Wire(LutBase(t) + kLutSource, 0, LutBase(t) + kLutNumber, 0, kSourceRpdo, 3);
  for (int k = 1; k <= 11; ++k)
    Write(0, LutBase(2) + kLutY, static_cast<std::uint8_t>(k), static_cast<std::uint16_t>(100 - 10 * (k - 1)),
          2);
  const std::uint16_t cond = LogicCondition(1, 1, 1);  // 3411h
  Write(0, cond, 1, kSourceRpdo, 1);
  Write(0, cond, 2, 1, 1);
  Write(0, cond, 3, kSourceConstant, 1);
  Write(0, cond, 4, 10, 1);
  Write(0, cond, 5, 2, 1);                            // >
  Write(0, LogicBase(1) + kLogicOperators, 2, 0, 1);  // B: default table
  Write(0, kLogicEnable, 1, 1, 1);
  Write(0, kReceivedPv, 3, 30, 2);
  Write(0, kReceivedPv, 1, 5, 2);  // 5 > 10.0 is false: B
  Advance(20ms);
  EXPECT_EQ(Read(0, kLogicSelectedTable, 1), 2);
  EXPECT_EQ(Read(0, kLogicOutput, 1, true), 700);  // table 2 at X 30: Y 70 -> 70.0 %
  Write(0, kReceivedPv, 1, 11, 2);
  Advance(20ms);
  EXPECT_EQ(Read(0, kLogicSelectedTable, 1), 1);
  EXPECT_EQ(Read(0, kLogicOutput, 1, true), 300);
  // A logic output as another block's source (Table 13: 8 = logic): LT04 reads LB1 (0..1000).
  Wire(LutBase(4) + kLutSource, 0, LutBase(4) + kLutNumber, 0, kSourceLogic, 1);
  for (int k = 11; k >= 1; --k)
    Write(0, LutBase(4) + kLutX, static_cast<std::uint8_t>(k), static_cast<std::uint32_t>(100 * (k - 1)), 4);
  Advance(20ms);
  EXPECT_EQ(LutOut(4), 30);
}

// §1.7, Table 23: inputs as % of their scaling x gain, functions in pairs, the last function is
// the block result, 4030h = 4021h + result x (4023h - 4021h). "+" (12), ">" (2), "/" by 0 (15).
TEST_F(ProgramTest, MathBlockOperators) {
  const std::uint16_t base = MathBase(1);
  // Inputs 1 and 2: received PV 1 and 2 with their 0..1000 (0.1) scaling; math scaling 0..100.0.
  for (const std::uint8_t in : {std::uint8_t{1}, std::uint8_t{2}}) {
    Wire(base + kMathSource, in, base + kMathNumber, in, kSourceRpdo, in);
    Write(0, base + kMathInputDigits, in, 1, 1);
    Write(0, base + kMathInputScaling2, in, 1000, 2);
  }
  Write(0, kMathEnable, 1, 1, 1);
  Write(0, kReceivedPv, 1, 300, 2);  // 30 %
  Write(0, kReceivedPv, 2, 200, 2);  // 20 %
  Advance(20ms);
  EXPECT_EQ(Read(0, kMathOutput, 1, true), 5000);  // 50.00 %
  Write(0, base + kMathGain, 2, static_cast<std::uint8_t>(-100), 1);
  Advance(20ms);
  EXPECT_EQ(Read(0, kMathOutput, 1, true), 1000);  // 30 - 20 = 10.00 %
  Write(0, base + kMathOperator, 1, 2, 1);         // >
  Write(0, base + kMathGain, 2, 100, 1);
  Advance(20ms);
  EXPECT_EQ(Read(0, kMathOutput, 1, true), 10000);  // TRUE = 100 %
  Write(0, base + kMathOperator, 1, 15, 1);         // /
  Write(0, kReceivedPv, 2, 0, 2);
  Advance(20ms);
  EXPECT_EQ(Read(0, kMathOutput, 1, true), 0);  // "a zero InB value will always result is a zero"
  // Disabled: output 0 (§3.4.54).
  Write(0, kReceivedPv, 2, 600, 2);
  Advance(20ms);
  EXPECT_EQ(Read(0, kMathOutput, 1, true), 5000);  // 30 / 60 = 0.5
  Write(0, kMathEnable, 1, 0, 1);
  Advance(20ms);
  EXPECT_EQ(Read(0, kMathOutput, 1, true), 0);
}

// §1.7: a math block as a lookup table's source, and the LUT's output as a math input (a chain
// over two cycles settles by itself).
TEST_F(ProgramTest, MathAndLookupTableChain) {
  Write(0, MathBase(2) + kMathSource, 1, kSourceLut, 1);
  Write(0, MathBase(2) + kMathNumber, 1, 5, 1);
  Write(0, MathBase(2) + kMathSource, 2, kSourceConstant, 1);
  Write(0, MathBase(2) + kMathNumber, 2, 1, 1);  // constant FALSE (0.0): 0 %
  Write(0, MathBase(2) + kMathInputScaling2, 1, 100, 2);
  Write(0, MathBase(2) + kMathInputDigits, 1, 0, 1);
  Write(0, kMathEnable, 2, 1, 1);
  Wire(LutBase(5) + kLutSource, 0, LutBase(5) + kLutNumber, 0, kSourceRpdo, 4);
  Write(0, kReceivedPv, 4, 80, 2);
  Advance(50ms);
  EXPECT_EQ(LutOut(5), 80);
  EXPECT_EQ(Read(0, kMathOutput, 2, true), 8000);  // 80 % of 0..100.00
  // Math 2 feeds LT06.
  Wire(LutBase(6) + kLutSource, 0, LutBase(6) + kLutNumber, 0, kSourceMath, 2);
  for (int k = 11; k >= 1; --k)
    Write(0, LutBase(6) + kLutX, static_cast<std::uint8_t>(k), static_cast<std::uint32_t>(1000 * (k - 1)), 4);
  Advance(50ms);
  EXPECT_EQ(LutOut(6), 80);
}

// §3.4.29-30: 2520h must stay below 2522h.
TEST_F(ProgramTest, ReceivedScalingOrder) {
  EXPECT_EQ(TryWrite(0, kReceivedScaling1, 1, 1000, 2),
            SdoAborted(kNode1, kReceivedScaling1, 1, kValueTooHigh));
  EXPECT_EQ(TryWrite(1, kReceivedScaling2, 1, 0, 2), SdoAborted(kNode2, kReceivedScaling2, 1, kValueTooLow));
  Write(1, kReceivedScaling1, 1, 999, 2);
}

}  // namespace
}  // namespace canfleet::devices::test
