#include "node/devices/blocks/logic_block.hpp"

namespace canfleet::devices::blocks {
namespace {

bool Compare(double a, CompareOp op, double b) {
  switch (op) {
    case CompareOp::kEqual:
      return a == b;
    case CompareOp::kNotEqual:
      return a != b;
    case CompareOp::kGreater:
      return a > b;
    case CompareOp::kGreaterOrEqual:
      return a >= b;
    case CompareOp::kLess:
      return a < b;
    case CompareOp::kLessOrEqual:
      return a <= b;
  }
  return false;
}

constexpr std::array<ConditionResult, 3> kNotEvaluated{
    ConditionResult::kNotApplicable, ConditionResult::kNotApplicable, ConditionResult::kNotApplicable};

}  // namespace

std::optional<CompareOp> DecodeCompareOp(std::uint8_t code) {
  if (code > static_cast<std::uint8_t>(CompareOp::kLessOrEqual)) return std::nullopt;
  return static_cast<CompareOp>(code);
}

std::optional<FunctionOperator> DecodeFunctionOperator(std::uint8_t code) {
  if (code > static_cast<std::uint8_t>(FunctionOperator::kEitherOfTwoAndThird)) return std::nullopt;
  return static_cast<FunctionOperator>(code);
}

LogicBlockParams DefaultLogicBlockParams(std::uint8_t block) {
  LogicBlockParams params;
  for (std::uint8_t f = 0; f < 3; ++f) {
    params.functions[f].table = static_cast<std::uint8_t>(3 * (block - 1) + f + 1);
    params.functions[f].op = f == 2 ? FunctionOperator::kDefaultTable : FunctionOperator::kAllTrue;
  }
  return params;
}

ConditionResult EvaluateCondition(const LogicCondition& condition, const ControlSources& sources) {
  const Signal a = sources.Resolve(condition.arg1);
  const Signal b = sources.Resolve(condition.arg2);
  if (!a.available || !b.available) return ConditionResult::kNotApplicable;
  if (a.error || b.error) return ConditionResult::kError;
  return Compare(a.value, condition.op, b.value) ? ConditionResult::kTrue : ConditionResult::kFalse;
}

bool EvaluateFunction(FunctionOperator op, const std::array<ConditionResult, 3>& results) {
  // Table 28: only operator 1 reads N/A as true; everything else needs a real True.
  const auto is_true = [&results](std::size_t i) { return results[i] == ConditionResult::kTrue; };
  const auto true_or_na = [&results](std::size_t i) {
    return results[i] == ConditionResult::kTrue || results[i] == ConditionResult::kNotApplicable;
  };
  switch (op) {
    case FunctionOperator::kDefaultTable:
      return true;
    case FunctionOperator::kAllTrue:
      return true_or_na(0) && true_or_na(1) && true_or_na(2);
    case FunctionOperator::kAnyTrue:
      return is_true(0) || is_true(1) || is_true(2);
    case FunctionOperator::kFirstTwoOrThird:
      return (is_true(0) && is_true(1)) || is_true(2);
    case FunctionOperator::kEitherOfTwoAndThird:
      return (is_true(0) || is_true(1)) && is_true(2);
  }
  return false;
}

const LogicResult& LogicBlock::Update(const LogicBlockParams& params, const ControlSources& sources) {
  LogicResult r;
  r.conditions = {kNotEvaluated, kNotEvaluated, kNotEvaluated};
  if (!params.enabled) {
    result_ = r;
    return result_;
  }

  std::uint8_t selected = 0;  // "If no default response has been setup, the Table A automatically
                              // becomes the default" (§1.8.2)
  for (std::uint8_t f = 0; f < 3; ++f) {
    const LogicFunction& fn = params.functions[f];
    if (fn.op != FunctionOperator::kDefaultTable) {
      for (std::size_t c = 0; c < 3; ++c)
        r.conditions[f][c] = EvaluateCondition(fn.conditions[c], sources);
    }
    if (EvaluateFunction(fn.op, r.conditions[f])) {
      selected = f;
      break;
    }
  }
  r.function = selected;
  r.table = params.functions[selected].table;

  const Signal table = sources.Resolve(SourceKind::kLookupTable, r.table);
  if (table.available) {
    r.output = Signal::Percent(table.ToPercent());
    r.output.error = table.error;
  } else {
    r.output = Signal::Percent(0.0);
    r.output.available = false;
  }
  result_ = r;
  return result_;
}

}  // namespace canfleet::devices::blocks
