// Math: valve UMAX020411A §1.9 Table 30 and §3.4.85-3.4.97, logger UMAX181001 §1.7 Table 23,
// encoder AX023241 §1.7 Table 13.
#include <gtest/gtest.h>

#include "node/devices/blocks/math_block.hpp"
#include "tests/unit/blocks/fake_sources.hpp"

namespace canfleet::devices::blocks::test {
namespace {

// RPDO extra values (valve source 1, numbers 13-24 -> 2500h) in 0..1000, 1 digit, like 2520h/2522h.
class ValveMathTest : public ::testing::Test {
 protected:
  ValveMathTest() {
    params_ = DefaultMathBlockParams(ValveMathProfile());
    params_.enabled = true;
    for (MathInputParams& in : params_.inputs) {
      in.scaling1 = 0;
      in.scaling2 = 1000;
      in.decimal_digits = 1;
    }
  }
  // Input `i` (1-based) reads RPDO value 12 + n at `percent` %.
  void Wire(std::size_t i, std::uint8_t n, double percent) {
    params_.inputs[i - 1].source = {1, static_cast<std::uint8_t>(12 + n)};
    Set(n, percent);
  }
  void Set(std::uint8_t n, double percent) {
    sources_.Set(SourceKind::kCanMessage, static_cast<std::uint8_t>(12 + n),
                 Ranged(percent * 10, 0, 1000, 1));
  }
  void Op(std::size_t function, MathOp op) {
    for (std::size_t code = 0; code < ValveMathProfile().operators.size(); ++code) {
      if (ValveMathProfile().operators[code] == op)
        params_.operators[function - 1] = static_cast<std::uint8_t>(code);
    }
  }
  double Run() { return block_.Update(params_, sources_.sources()).value; }

  FakeSources sources_{ValveSourceTypes()};
  MathBlockParams params_;
  MathBlock block_{ValveMathProfile(), 1};
};

// §1.9 example: a joystick (input 1, gain 0.75) plus a potentiometer (input 2, gain 0.25) "will
// give a command from 0 to 100%"; output scaled to 4021h..4023h = 0..10000 (0.01 %).
TEST_F(ValveMathTest, JoystickPlusPotentiometerExample) {
  Wire(1, 1, 100);
  Wire(2, 2, 100);
  params_.inputs[0].gain = 0.75;
  params_.inputs[1].gain = 0.25;
  EXPECT_EQ(Run(), 10000);
  Set(1, 50);
  Set(2, 0);
  EXPECT_EQ(Run(), 3750);
  EXPECT_EQ(block_.Output().max, 10000);
  EXPECT_EQ(block_.Output().decimal_digits, 2);
}

// §1.9: "consider all 6 inputs to be CANopen Messages 1 to 6 ... the result of the Math Block will
// be the result of Function 3, thus, ignoring Functions 1 and 2."
TEST_F(ValveMathTest, ResultIsTheLastFunctionUsed) {
  for (std::uint8_t i = 1; i <= 6; ++i)
    Wire(i, i, 10.0 * i);
  EXPECT_EQ(Run(), 10000);  // F3 = 50 % + 60 % = 110 %, saturated at 100 %
  EXPECT_DOUBLE_EQ(*block_.FunctionResult(0), 0.3);
  Set(5, 20);
  Set(6, 10);
  EXPECT_EQ(Run(), 3000);
}

// §1.9: "For a valid result in each Function, both inputs must be [used] ... Otherwise, the
// corresponding Function is ignored."
TEST_F(ValveMathTest, FunctionWithAnUnusedInputIsIgnored) {
  Wire(1, 1, 20);
  Wire(2, 2, 30);
  Wire(3, 3, 90);  // F2 has no input 4
  EXPECT_EQ(Run(), 5000);
  EXPECT_EQ(block_.FunctionResult(1), std::nullopt);
  params_.inputs[0].source = {};
  EXPECT_EQ(Run(), 0);  // nothing used
}

// §1.9: "When dividing, a zero InB value will always result in a zero output"; "When subtracting,
// a negative result will always be treated as a zero".
TEST_F(ValveMathTest, DivisionByZeroAndNegativeDifferenceGiveZero) {
  Wire(1, 1, 40);
  Wire(2, 2, 0);
  Op(1, MathOp::kDivide);
  EXPECT_EQ(Run(), 0);
  Set(2, 80);
  EXPECT_EQ(Run(), 5000);  // 0.4 / 0.8
  Op(1, MathOp::kSubtract);
  EXPECT_EQ(Run(), 0);
  Set(2, 10);
  EXPECT_EQ(Run(), 3000);
}

// §1.9: "For logical operators (6 to 11), any SCALED input greater than or equal to 0.5 is treated
// as a TRUE input ... the result ... will always be 0 (FALSE) or 1 (TRUE)" (1 = 100 %).
TEST_F(ValveMathTest, LogicOperatorsUseTheHalfThreshold) {
  Wire(1, 1, 50);
  Wire(2, 2, 49.9);
  Op(1, MathOp::kAnd);
  EXPECT_EQ(Run(), 0);
  Op(1, MathOp::kOr);
  EXPECT_EQ(Run(), 10000);
  Op(1, MathOp::kXor);
  EXPECT_EQ(Run(), 10000);
  Op(1, MathOp::kNand);
  EXPECT_EQ(Run(), 10000);
  Op(1, MathOp::kXnor);
  EXPECT_EQ(Run(), 0);
  Op(1, MathOp::kNor);
  EXPECT_EQ(Run(), 0);
  Op(1, MathOp::kGreater);
  EXPECT_EQ(Run(), 10000);
  Op(1, MathOp::kEqual);
  EXPECT_EQ(Run(), 0);
  Op(1, MathOp::kMin);
  EXPECT_EQ(Run(), 4990);
}

// §1.9: "Error data (i.e. input measured out of range) is always treated as a 0.0 input".
TEST_F(ValveMathTest, FaultedInputCountsAsZero) {
  Wire(1, 1, 40);
  Wire(2, 2, 30);
  sources_.Set(SourceKind::kCanMessage, 14, Faulted(Ranged(300, 0, 1000, 1)));
  EXPECT_EQ(Run(), 4000);
  EXPECT_FALSE(block_.Output().error);
}

// §1.9 4y02h: an input whose source is this math block and whose function number is 1..3 reads
// that function: F3 = F1 + In6. A function not yet run this tick gives last tick's value.
TEST_F(ValveMathTest, FunctionNumberChainsWithinTheBlock) {
  Wire(1, 1, 20);
  Wire(2, 2, 10);
  params_.inputs[4].source = {6, 1};  // math 1 = this block
  params_.inputs[4].function = 1;
  Wire(6, 6, 5);
  EXPECT_EQ(Run(), 3500);

  MathBlockParams loop = params_;
  loop.inputs[0].source = {6, 1};  // In1 = F3: not yet run this tick
  loop.inputs[0].function = 3;
  EXPECT_EQ(block_.Update(loop, sources_.sources()).value, 5000);  // F1 = 0.35 + 0.1, F3 = F1 + 0.05
  EXPECT_EQ(block_.Update(loop, sources_.sources()).value, 6500);  // F1 = 0.5 + 0.1
}

// §1.9: inputs are made % with 4y20h/4y22h after the 4y03h shift, whatever the source's own
// digits: AI 2500 mV (3 digits) in 0.00..5.00 V (2 digits) is 50 %; 4021h..4023h scale the output.
TEST_F(ValveMathTest, ScalingUsesEachSidesDigits) {
  sources_.Set(SourceKind::kAnalogInput, 1, Ranged(2500, 500, 4500, 3));
  params_.inputs[0] = {{2, 1}, 0, 0, 500, 2, 1.0};
  Wire(2, 2, 0);
  params_.output_scaling1 = 1000;
  params_.output_scaling2 = 2000;
  EXPECT_EQ(Run(), 1500);
  EXPECT_EQ(block_.Output().min, 1000);
}

// §3.4.85 4000h: a disabled block outputs 0.
TEST_F(ValveMathTest, DisabledBlockOutputsZero) {
  Wire(1, 1, 40);
  Wire(2, 2, 30);
  params_.enabled = false;
  EXPECT_EQ(Run(), 0);
}

// Table 30 (valve, 18 operators, default 12 "+") vs Table 13 (encoder, 16 operators with MAX-MIN,
// default 9 "+"); the logger's Table 23 is the valve's list.
TEST(MathProfileTest, OperatorSetsDifferPerProduct) {
  const MathProfile valve = ValveMathProfile();
  const MathProfile encoder = EncoderMathProfile();
  EXPECT_EQ(valve.DecodeOperator(17), MathOp::kMax);
  EXPECT_EQ(valve.DecodeOperator(18), std::nullopt);
  EXPECT_EQ(valve.DecodeOperator(7), MathOp::kNor);
  EXPECT_EQ(encoder.DecodeOperator(7), MathOp::kAnd);
  EXPECT_EQ(encoder.DecodeOperator(15), MathOp::kMaxMinusMin);
  EXPECT_EQ(encoder.DecodeOperator(16), std::nullopt);
  EXPECT_EQ(DataLoggerMathProfile().DecodeOperator(12), MathOp::kAdd);
  EXPECT_EQ(DefaultMathBlockParams(valve).operators, (std::vector<std::uint8_t>{12, 12, 12}));
  EXPECT_EQ(DefaultMathBlockParams(encoder).operators, (std::vector<std::uint8_t>{9, 9, 9, 9}));
  EXPECT_EQ(DefaultMathBlockParams(encoder).inputs.size(), 5u);
}

// Encoder §1.7: "a zero divider will always result in a 100% output"; logic TRUE at >= 1;
// MAX-MIN; arithmetic saturates at 0..100 %. The valve divides by zero to 0.
TEST(MathProfileTest, EncoderOperatorRules) {
  const MathProfile encoder = EncoderMathProfile();
  const MathProfile valve = ValveMathProfile();
  EXPECT_DOUBLE_EQ(ApplyMathOp(MathOp::kDivide, 0.4, 0.0, encoder), 1.0);
  EXPECT_DOUBLE_EQ(ApplyMathOp(MathOp::kDivide, 0.4, 0.0, valve), 0.0);
  EXPECT_DOUBLE_EQ(ApplyMathOp(MathOp::kOr, 0.6, 0.0, encoder), 0.0);
  EXPECT_DOUBLE_EQ(ApplyMathOp(MathOp::kOr, 0.6, 0.0, valve), 1.0);
  EXPECT_DOUBLE_EQ(ApplyMathOp(MathOp::kAnd, 1.0, 1.0, encoder), 1.0);
  EXPECT_DOUBLE_EQ(ApplyMathOp(MathOp::kMaxMinusMin, 0.2, 0.7, encoder), 0.5);
  EXPECT_DOUBLE_EQ(ApplyMathOp(MathOp::kAdd, 0.7, 0.7, encoder), 1.0);
  EXPECT_DOUBLE_EQ(ApplyMathOp(MathOp::kAdd, 0.7, 0.7, valve), 1.4);
  EXPECT_DOUBLE_EQ(ApplyMathOp(MathOp::kSubtract, -0.5, 0.2, valve), 0.0);
}

// Encoder §1.7: "Math Block Output = (((InA op1 InB1) op2 InB2) op3 InB3)" over five inputs; an
// unused input B "goes through function unchanged". Encoder numbering: RPDO = 1, numbers 1-5.
TEST(MathProfileTest, EncoderChainsItsFunctions) {
  FakeSources encoder(EncoderSourceTypes());
  MathBlockParams params = DefaultMathBlockParams(EncoderMathProfile());
  params.enabled = true;
  for (std::uint8_t i = 1; i <= 5; ++i) {
    encoder.Set(SourceKind::kCanMessage, i, Ranged(10.0 * i, 0, 100));
    params.inputs[i - 1] = {{1, i}, 0, 0, 100, 0, 1.0};
  }
  params.operators = {9, 9, 10, 11};  // ((0.1 + 0.2) + 0.3 - 0.4) x 0.5 = 0.1
  MathBlock block(EncoderMathProfile(), 1);
  EXPECT_EQ(block.Update(params, encoder.sources()).value, 1000);
  params.inputs[2].source = {};  // (0.1 + 0.2) passes op2, then - 0.4 = -0.1 -> 0
  EXPECT_EQ(block.Update(params, encoder.sources()).value, 0);
  params.operators[2] = 14;  // MAX with 0.4, x 0.5 = 0.2
  EXPECT_EQ(block.Update(params, encoder.sources()).value, 2000);
}

}  // namespace
}  // namespace canfleet::devices::blocks::test
