// The programmable blocks of the AX023241 on their objects: math (1.7, Table 13, C3-1.4.50-1.4.61),
// lookup tables (1.6, C3-1.4.37-1.4.45), PID (1.8, Table 14, C3-1.3.32-1.3.37, C3-1.4.24-1.4.32)
// and the (source, number) wiring with its write rules (1.3, Tables 6 and 7).
#include "tests/unit/encoder/encoder_fixture.hpp"

namespace canfleet::devices::encoder::test {
namespace {

class FunctionBlocksTest : public EncoderTest {
 protected:
  /// Source `source`, number `number` into the pair at (source_index, number_index), number first
  /// (1.3: the number depends on the source).
  void Wire(std::uint16_t source_index, std::uint16_t number_index, std::uint8_t sub, std::uint8_t source,
            std::uint8_t number) {
    Write(number_index, sub, number, 1);
    Write(source_index, sub, source, 1);
  }
  void WriteConstant(std::uint8_t sub, float value) { Write(0x5010, sub, Real32Bits(value), 4); }
  /// Math block 1: input 1 = constant 7 (50.0), input 2 = constant 3 (10.0), both read as 0..100.00.
  void MathOfTwoConstants() {
    Wire(0x4100, 0x4101, 1, 9, 7);
    Wire(0x4100, 0x4101, 2, 9, 3);
    Write(0x4000, 1, 1, 1);
  }
};

// 1.7: inputs as % of 4x20h..4x22h (0..100.00) times 4x40h / 100; Out = (In1 op1 In2) ... scaled
// to 4021h..4023h (0..10000): 50 % + 10 % = 60 % -> 6000.
TEST_F(FunctionBlocksTest, MathAddsTwoConstants) {
  MathOfTwoConstants();
  Advance(1ms);
  EXPECT_EQ(Read(0x4030, 1, true), 6000);
  EXPECT_EQ(Read(0x4030, 2, true), 0);  // disabled (4000h.2 = 0)
}

// Table 13: 15 MAX-MIN, 12 "/" saturating at 100 %, "/" by zero = 100 %, 7 AND (TRUE at >= 1),
// gain 4x40h (-1.0..1.0).
TEST_F(FunctionBlocksTest, MathOperatorsOfThisProduct) {
  MathOfTwoConstants();
  Write(0x4150, 1, 15, 1);
  Advance(1ms);
  EXPECT_EQ(Read(0x4030, 1, true), 4000);
  Write(0x4150, 1, 12, 1);
  Advance(1ms);
  EXPECT_EQ(Read(0x4030, 1, true), 10000);
  Write(0x4101, 2, 1, 1);  // input 2 = FALSE (0.0)
  Advance(1ms);
  EXPECT_EQ(Read(0x4030, 1, true), 10000);
  Write(0x4150, 1, 7, 1);
  Advance(1ms);
  EXPECT_EQ(Read(0x4030, 1, true), 0);
  Write(0x4150, 1, 9, 1);
  Write(0x4140, 1, 50, 1);  // gain 0.5
  Advance(1ms);
  EXPECT_EQ(Read(0x4030, 1, true), 2500);
  EXPECT_EQ(TryWrite(0x4140, 1, 101, 1), SdoAborted(0x4140, 1, 0x06090031));
}

// 1.6.4: a math block (0 to 100.00 %) drives the default table (0 to 100): ramp-to interpolates,
// jump-to gives Y_N on the segment (X_N-1, X_N]; the table then controls output 2 through its Y
// range (lowest..highest used Y, 1.6.2).
TEST_F(FunctionBlocksTest, LookupTableFromMathDrivesAnOutput) {
  MathOfTwoConstants();
  WriteConstant(7, 45.0F);  // 45 % + 10 % = 55 %
  Wire(0x3010, 0x3011, 0, 6, 1);
  Advance(1ms);
  EXPECT_EQ(Read(0x3018, 0, true), 55);
  Write(0x3015, 6, 1, 1);  // segment X5..X6 (50..60): jump to Y6
  Advance(1ms);
  EXPECT_EQ(Read(0x3018, 0, true), 60);
  Write(0x2330, 2, 0, 2);
  Write(0x7323, 2, 2000, 2);
  Wire(0x2340, 0x2341, 2, 5, 1);
  Advance(1ms);
  EXPECT_EQ(Out("OUT2.current_mA"), 1200);
}

// Tables 6/7: numbers are checked against their source; a source that makes the stored number
// invalid is refused (write the number first). Lookup table [1...3] has only tables 1-2 here.
TEST_F(FunctionBlocksTest, SourceNumberPairsAreChecked) {
  EXPECT_EQ(TryWrite(0x2341, 1, 9, 1), SdoAborted(0x2341, 1, 0x06090031));
  Write(0x2341, 1, 6, 1);  // received CAN message 6 = 2500h.4
  EXPECT_EQ(TryWrite(0x2340, 1, 2, 1), SdoAborted(0x2340, 1, 0x06040043));
  EXPECT_EQ(TryWrite(0x2341, 1, 0, 1), SdoAborted(0x2341, 1, 0x06090032));
  Write(0x3011, 0, 3, 1);  // source 0: the number is not looked at
  EXPECT_EQ(TryWrite(0x3010, 0, 5, 1), SdoAborted(0x3010, 0, 0x06040043));
}

// Table 6 "Received CAN Message" 3-8 = 2500h.1-6 with the limits 2520h..2522h (RPDO2 maps
// 2500h.1-4, C3-1.2.17).
TEST_F(FunctionBlocksTest, ExtraReceivedValueControlsAnOutput) {
  Write(0x2520, 1, 0, 2);
  Write(0x2522, 1, 1000, 2);
  Write(0x1401, 1, 0x40000305, 4);
  Write(0x2330, 1, 0, 2);
  Write(0x2331, 1, 0, 2);
  Wire(0x2340, 0x2341, 1, 1, 3);
  Start();
  Send("305#F401000000000000");  // 2500h.1 = 500 of 0..1000
  Advance(1ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 2500);  // 50 % of 0..5000 mA, held at 2500
  Write(0x7323, 1, 2000, 2);
  Advance(1ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 1000);
}

// 1.8: a PID on output 1's current: target = constant 1250.0 (a constant takes the feedback's
// limits), feedback = output current feedback 1 (0..2500 mA), output 1 controlled by the PID. The
// loop settles within the tolerance 2450h (1.0 %) and the device then sleeps.
TEST_F(FunctionBlocksTest, PidClosesTheLoopOnTheOutputCurrentAndSettles) {
  WriteConstant(7, 1250.0F);
  Write(0x2452, 0, 0, 2);  // no derivative action
  Wire(0x2453, 0x2454, 0, 9, 7);
  Wire(0x2455, 0x2456, 0, 4, 1);
  Write(0x2330, 1, 0, 2);
  Write(0x2331, 1, 0, 2);
  Write(0x7323, 1, 2500, 2);
  Wire(0x2340, 0x2341, 1, 8, 1);
  Advance(5000ms);
  EXPECT_NEAR(Out("OUT1.current_mA"), 1250, 30);
  EXPECT_NEAR(static_cast<double>(Read(0x2460, 0, true)), 500, 12);
  EXPECT_FALSE(device().Ticking());
}

// Table 14 "Setpoint Control": 2453h becomes 9 (control constant) and cannot be changed.
TEST_F(FunctionBlocksTest, SetpointControlLocksTheTargetToAConstant) {
  Write(0x2457, 0, 1, 1);
  EXPECT_EQ(Read(0x2453, 0), 9);
  EXPECT_EQ(TryWrite(0x2453, 0, 2, 1), SdoAborted(0x2453, 0, 0x08000022));
  Write(0x2457, 0, 0, 1);
  Write(0x2454, 0, 1, 1);
  Write(0x2453, 0, 2, 1);
}

// 1.5: 5010h sub 1 FALSE and sub 2 TRUE are fixed; the others are the user's.
TEST_F(FunctionBlocksTest, FixedConstants) {
  EXPECT_EQ(TryWrite(0x5010, 2, Real32Bits(5.0F), 4), SdoAborted(0x5010, 2, 0x06090030));
  Write(0x5010, 2, Real32Bits(1.0F), 4);
  Write(0x5010, 3, Real32Bits(5.0F), 4);
}

}  // namespace
}  // namespace canfleet::devices::encoder::test
