// Programmable logic: valve UMAX020411A §1.8 (Tables 24-29), logger UMAX181001 §1.6 (Tables
// 17-22, the same rules with the logger's source numbering).
#include <gtest/gtest.h>

#include "node/devices/blocks/logic_block.hpp"
#include "tests/unit/blocks/fake_sources.hpp"

namespace canfleet::devices::blocks::test {
namespace {

using C = ConditionResult;
using F = FunctionOperator;

constexpr std::array<C, 3> Results(C a, C b, C c) {
  return {a, b, c};
}

// Table 28, operator 1: "If any condition equals False or Error, the table is not selected. An N/A
// is treated like a True."
TEST(LogicBlockTest, AndTreatsNotApplicableAsTrue) {
  EXPECT_TRUE(EvaluateFunction(F::kAllTrue, Results(C::kTrue, C::kNotApplicable, C::kNotApplicable)));
  EXPECT_TRUE(
      EvaluateFunction(F::kAllTrue, Results(C::kNotApplicable, C::kNotApplicable, C::kNotApplicable)));
  EXPECT_FALSE(EvaluateFunction(F::kAllTrue, Results(C::kTrue, C::kError, C::kTrue)));
  EXPECT_FALSE(EvaluateFunction(F::kAllTrue, Results(C::kTrue, C::kFalse, C::kNotApplicable)));
}

// Table 28, operators 2-4: "Error or N/A results are treated as False".
TEST(LogicBlockTest, OtherOperatorsTreatErrorAndNotApplicableAsFalse) {
  EXPECT_TRUE(EvaluateFunction(F::kAnyTrue, Results(C::kFalse, C::kNotApplicable, C::kTrue)));
  EXPECT_FALSE(EvaluateFunction(F::kAnyTrue, Results(C::kNotApplicable, C::kError, C::kNotApplicable)));
  EXPECT_TRUE(EvaluateFunction(F::kFirstTwoOrThird, Results(C::kTrue, C::kTrue, C::kFalse)));
  EXPECT_TRUE(EvaluateFunction(F::kFirstTwoOrThird, Results(C::kFalse, C::kError, C::kTrue)));
  EXPECT_FALSE(EvaluateFunction(F::kFirstTwoOrThird, Results(C::kTrue, C::kNotApplicable, C::kFalse)));
  EXPECT_TRUE(EvaluateFunction(F::kEitherOfTwoAndThird, Results(C::kFalse, C::kTrue, C::kTrue)));
  EXPECT_FALSE(EvaluateFunction(F::kEitherOfTwoAndThird, Results(C::kTrue, C::kTrue, C::kNotApplicable)));
  EXPECT_TRUE(EvaluateFunction(F::kDefaultTable, Results(C::kFalse, C::kError, C::kFalse)));
}

class LogicConditionTest : public ::testing::Test {
 protected:
  LogicConditionTest() {
    valve_.Set(SourceKind::kAnalogInput, 1, Ranged(2500, 500, 4500, 3));  // 2.5 V in mV
    valve_.Set(SourceKind::kAnalogInput, 2, Faulted(Ranged(100, 500, 4500, 3)));
    valve_.Set(SourceKind::kConstant, 3, Signal::Constant(2000));
    valve_.Set(SourceKind::kConstant, 4, Signal::Constant(2500));
  }
  ConditionResult Eval(SourceRef a, CompareOp op, SourceRef b) {
    return EvaluateCondition({a, b, op}, valve_.sources());
  }
  FakeSources valve_{ValveSourceTypes()};
};

// §1.8.1: argument 2 may be a constant "in the same resolution as Argument 1": AI1 = 2500 mV is
// compared with constants 2000 and 2500 as raw values. Table 25 operators 0-5.
TEST_F(LogicConditionTest, ComparesRawValuesWithTable25Operators) {
  EXPECT_EQ(Eval({2, 1}, CompareOp::kGreater, {3, 3}), C::kTrue);
  EXPECT_EQ(Eval({2, 1}, CompareOp::kLess, {3, 3}), C::kFalse);
  EXPECT_EQ(Eval({2, 1}, CompareOp::kEqual, {3, 4}), C::kTrue);
  EXPECT_EQ(Eval({2, 1}, CompareOp::kNotEqual, {3, 4}), C::kFalse);
  EXPECT_EQ(Eval({2, 1}, CompareOp::kGreaterOrEqual, {3, 4}), C::kTrue);
  EXPECT_EQ(Eval({2, 1}, CompareOp::kLessOrEqual, {3, 3}), C::kFalse);
}

// Table 26: Error when an argument "was reported as being in an error state"; N/A when an argument
// is "Control Source Not Used" (that wins: the condition is disabled).
TEST_F(LogicConditionTest, ErrorAndNotApplicableFollowTable26) {
  EXPECT_EQ(Eval({2, 2}, CompareOp::kLess, {3, 3}), C::kError);
  EXPECT_EQ(Eval({2, 1}, CompareOp::kLess, {0, 0}), C::kNotApplicable);
  EXPECT_EQ(Eval({0, 0}, CompareOp::kEqual, {0, 0}), C::kNotApplicable);
  EXPECT_EQ(Eval({2, 2}, CompareOp::kEqual, {0, 0}), C::kNotApplicable);
}

// Table 25 has 6 operators, Table 27 has 5 function operators (SDO validation).
TEST(LogicBlockTest, OperatorCodesAreValidated) {
  EXPECT_EQ(DecodeCompareOp(5), CompareOp::kLessOrEqual);
  EXPECT_EQ(DecodeCompareOp(6), std::nullopt);
  EXPECT_EQ(DecodeFunctionOperator(4), F::kEitherOfTwoAndThird);
  EXPECT_EQ(DecodeFunctionOperator(5), std::nullopt);
}

// Table 29 default tables and §1.8.2 default operators (A, B: And; C: Default Table).
TEST(LogicBlockTest, DefaultsFollowTable29) {
  const LogicBlockParams lb2 = DefaultLogicBlockParams(2);
  EXPECT_FALSE(lb2.enabled);
  EXPECT_EQ(lb2.functions[0].table, 4);
  EXPECT_EQ(lb2.functions[1].table, 5);
  EXPECT_EQ(lb2.functions[2].table, 6);
  EXPECT_EQ(lb2.functions[0].op, F::kAllTrue);
  EXPECT_EQ(lb2.functions[2].op, F::kDefaultTable);
}

// §1.8.2's example, one relevant condition ("the Engine RPM be below a certain value") with the
// Or operator: table A below 1500 rpm, the default table B otherwise. Logger numbering (AI = 2,
// constant = 5, LUT = 6) to show the block reads kinds, not codes.
class EngineRpmExample : public ::testing::Test {
 protected:
  EngineRpmExample() {
    params_.enabled = true;
    params_.functions[0].op = F::kAnyTrue;
    params_.functions[0].conditions[0] = {{2, 1}, {5, 3}, CompareOp::kLess};
    params_.functions[0].table = 1;
    params_.functions[1].op = F::kDefaultTable;
    params_.functions[1].table = 2;
    logger_.Set(SourceKind::kConstant, 3, Signal::Constant(15000));  // 1500.0 rpm in 0.1 rpm
    logger_.Set(SourceKind::kLookupTable, 1, Ranged(30, 0, 100));
    logger_.Set(SourceKind::kLookupTable, 2, Ranged(50, -50, 150));
  }
  void Rpm(double tenths) { logger_.Set(SourceKind::kAnalogInput, 1, Ranged(tenths, 1000, 30000, 1)); }

  FakeSources logger_{DataLoggerSourceTypes()};
  LogicBlockParams params_;
  LogicBlock block_;
};

// §1.8.2 selection and §1.8.3 output: the selected table's output as % of its Y range, 0.1 %.
TEST_F(EngineRpmExample, SelectsTableAOnlyBelowTheLimit) {
  Rpm(9000);
  const LogicResult& low = block_.Update(params_, logger_.sources());
  EXPECT_EQ(low.function, 0);
  EXPECT_EQ(low.table, 1);
  EXPECT_EQ(low.output.value, 300);  // 30 in 0..100 = 30.0 %
  EXPECT_EQ(low.conditions[0][1], C::kNotApplicable);

  Rpm(20000);
  const LogicResult& high = block_.Update(params_, logger_.sources());
  EXPECT_EQ(high.function, 1);
  EXPECT_EQ(high.table, 2);
  EXPECT_EQ(high.output.value, 500);  // 50 in -50..150 = 50.0 %
}

// Figure 19: "Only if a lower indexed table (A, B, C) has not been selected will the conditions
// for the next table be looked at"; none true -> "Table A automatically becomes the default".
TEST_F(EngineRpmExample, FirstTrueFunctionWinsAndTableAIsTheFallback) {
  Rpm(9000);
  params_.functions[1].op = F::kAnyTrue;
  params_.functions[1].conditions[0] = {{2, 1}, {5, 3}, CompareOp::kLess};
  EXPECT_EQ(block_.Update(params_, logger_.sources()).table, 1);
  EXPECT_EQ(block_.Result().conditions[1][0], C::kNotApplicable);  // B never evaluated

  Rpm(20000);
  params_.functions[2].op = F::kAnyTrue;  // no default table at all
  const LogicResult& r = block_.Update(params_, logger_.sources());
  EXPECT_EQ(r.function, 0);
  EXPECT_EQ(r.table, 1);
  EXPECT_EQ(r.conditions[1][0], C::kFalse);
}

// §1.8.3: a selected table without an X-axis source makes the output "Not Available"; a faulted
// table input passes its error on.
TEST_F(EngineRpmExample, OutputIsNotAvailableWithoutTableSource) {
  Rpm(9000);
  logger_.Set(SourceKind::kLookupTable, 1, Signal::NotAvailable());
  EXPECT_FALSE(block_.Update(params_, logger_.sources()).output.available);
  logger_.Set(SourceKind::kLookupTable, 1, Faulted(Ranged(30, 0, 100)));
  EXPECT_TRUE(block_.Update(params_, logger_.sources()).output.error);
}

// §3.4.71 3300h: "They are all disabled by default": nothing is selected.
TEST_F(EngineRpmExample, DisabledBlockSelectsNothing) {
  Rpm(9000);
  params_.enabled = false;
  const LogicResult& r = block_.Update(params_, logger_.sources());
  EXPECT_EQ(r.table, 0);
  EXPECT_EQ(r.function, std::nullopt);
  EXPECT_FALSE(r.output.available);
}

}  // namespace
}  // namespace canfleet::devices::blocks::test
