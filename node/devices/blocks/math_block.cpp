#include "node/devices/blocks/math_block.hpp"

#include <algorithm>
#include <cmath>

namespace canfleet::devices::blocks {
namespace {

using Op = MathOp;

// Valve Table 30 / logger Table 23, in object-value order.
constexpr std::array kValveOperators{
    Op::kEqual, Op::kNotEqual, Op::kGreater,  Op::kGreaterOrEqual, Op::kLess, Op::kLessOrEqual,
    Op::kOr,    Op::kNor,      Op::kAnd,      Op::kNand,           Op::kXor,  Op::kXnor,
    Op::kAdd,   Op::kSubtract, Op::kMultiply, Op::kDivide,         Op::kMin,  Op::kMax};

// Encoder Table 13.
constexpr std::array kEncoderOperators{Op::kEqual,  Op::kNotEqual,    Op::kGreater,  Op::kGreaterOrEqual,
                                       Op::kLess,   Op::kLessOrEqual, Op::kOr,       Op::kAnd,
                                       Op::kXor,    Op::kAdd,         Op::kSubtract, Op::kMultiply,
                                       Op::kDivide, Op::kMin,         Op::kMax,      Op::kMaxMinusMin};

// Fractions come out of divisions and gains: equal to within rounding is equal.
constexpr double kEqualWithin = 1e-9;

double Bool(bool b) {
  return b ? 1.0 : 0.0;
}

}  // namespace

MathProfile ValveMathProfile() {
  MathProfile p;
  p.operators = kValveOperators;
  return p;
}

MathProfile DataLoggerMathProfile() {
  return ValveMathProfile();
}

MathProfile EncoderMathProfile() {
  MathProfile p;
  p.operators = kEncoderOperators;
  p.topology = MathTopology::kChain;
  p.inputs = 5;
  p.logic_true_threshold = 1.0;
  p.divide_by_zero = 1.0;
  p.negative_difference_is_zero = false;
  p.saturate_each_function = true;
  return p;
}

MathBlockParams DefaultMathBlockParams(const MathProfile& profile) {
  MathBlockParams params;
  params.inputs.resize(profile.inputs);
  std::uint8_t add = 0;
  for (std::size_t i = 0; i < profile.operators.size(); ++i) {
    if (profile.operators[i] == MathOp::kAdd) add = static_cast<std::uint8_t>(i);
  }
  params.operators.assign(profile.Functions(), add);
  return params;
}

double ApplyMathOp(MathOp op, double a, double b, const MathProfile& profile) {
  const bool ta = a >= profile.logic_true_threshold;
  const bool tb = b >= profile.logic_true_threshold;
  double r = 0.0;
  switch (op) {
    case Op::kEqual:
      return Bool(std::abs(a - b) <= kEqualWithin);
    case Op::kNotEqual:
      return Bool(std::abs(a - b) > kEqualWithin);
    case Op::kGreater:
      return Bool(a > b + kEqualWithin);
    case Op::kGreaterOrEqual:
      return Bool(a >= b - kEqualWithin);
    case Op::kLess:
      return Bool(a < b - kEqualWithin);
    case Op::kLessOrEqual:
      return Bool(a <= b + kEqualWithin);
    case Op::kOr:
      return Bool(ta || tb);
    case Op::kNor:
      return Bool(!ta && !tb);
    case Op::kAnd:
      return Bool(ta && tb);
    case Op::kNand:
      return Bool(!(ta && tb));
    case Op::kXor:
      return Bool(ta != tb);
    case Op::kXnor:
      return Bool(ta == tb);
    case Op::kAdd:
      r = a + b;
      break;
    case Op::kSubtract:
      r = a - b;
      if (profile.negative_difference_is_zero && r < 0.0) r = 0.0;
      break;
    case Op::kMultiply:
      r = a * b;
      break;
    case Op::kDivide:
      r = b == 0.0 ? profile.divide_by_zero : a / b;
      break;
    case Op::kMin:
      r = std::min(a, b);
      break;
    case Op::kMax:
      r = std::max(a, b);
      break;
    case Op::kMaxMinusMin:
      r = std::max(a, b) - std::min(a, b);
      break;
  }
  if (profile.saturate_each_function) r = std::clamp(r, 0.0, 1.0);
  return r;
}

double MathBlock::ReadInput(const MathInputParams& input, const ControlSources& sources) const {
  const Signal s = sources.Resolve(input.source);
  if (!s.available || s.error) return 0.0;  // faulted: "treated as a 0.0 input"
  const double value = s.value / PowerOfTen(s.decimal_digits);
  const double scale = PowerOfTen(input.decimal_digits);
  const double lo = input.scaling1 / scale;
  const double hi = input.scaling2 / scale;
  if (hi == lo) return 0.0;
  return std::clamp((value - lo) / (hi - lo), 0.0, 1.0) * input.gain;
}

double MathBlock::EvaluatePairs(const MathBlockParams& params, const ControlSources& sources) {
  const std::size_t count = std::min({profile_.Functions(), functions_.size(), params.inputs.size() / 2});
  // Starts as the previous tick's results and is overwritten in function order, so a chained
  // input sees this tick's value of an earlier function and last tick's of a later one.
  std::array<std::optional<double>, 8> now = functions_;
  std::optional<double> last;
  const auto read = [&](const MathInputParams& in) {
    const bool chained = sources.KindOf(in.source.source) == SourceKind::kMath &&
                         in.source.number == own_number_ && in.function >= 1 && in.function <= count;
    if (!chained) return ReadInput(in, sources);
    return now[in.function - 1u].value_or(0.0) * in.gain;
  };
  for (std::size_t k = 0; k < count; ++k) {
    const MathInputParams& a = params.inputs[2 * k];
    const MathInputParams& b = params.inputs[2 * k + 1];
    const std::optional<MathOp> op =
        k < params.operators.size() ? profile_.DecodeOperator(params.operators[k]) : std::nullopt;
    const bool used = sources.KindOf(a.source.source) != SourceKind::kNotUsed &&
                      sources.KindOf(b.source.source) != SourceKind::kNotUsed;
    if (!used || !op) {
      now[k].reset();  // "Otherwise, the corresponding Function is ignored."
      continue;
    }
    now[k] = ApplyMathOp(*op, read(a), read(b), profile_);
    last = now[k];
  }
  functions_ = now;
  return last.value_or(0.0);
}

double MathBlock::EvaluateChain(const MathBlockParams& params, const ControlSources& sources) {
  if (params.inputs.empty()) return 0.0;
  const std::size_t count = std::min({profile_.Functions(), functions_.size(), params.inputs.size() - 1});
  double running = ReadInput(params.inputs[0], sources);
  for (std::size_t k = 0; k < count; ++k) {
    const MathInputParams& b = params.inputs[k + 1];
    const std::optional<MathOp> op =
        k < params.operators.size() ? profile_.DecodeOperator(params.operators[k]) : std::nullopt;
    // "If Function X Input B Source is set to 0 'Control not used' signal goes through function
    // unchanged." (encoder §1.7)
    if (sources.KindOf(b.source.source) != SourceKind::kNotUsed && op) {
      running = ApplyMathOp(*op, running, ReadInput(b, sources), profile_);
    }
    functions_[k] = running;
  }
  return running;
}

const Signal& MathBlock::Update(const MathBlockParams& params, const ControlSources& sources) {
  Signal out;
  out.min = params.output_scaling1;
  out.max = params.output_scaling2;
  out.decimal_digits = params.output_digits;
  if (!params.enabled) {
    functions_ = {};
    result_ = 0.0;
    output_ = out;  // value 0: "when disabled the output is 0"
    return output_;
  }
  const double r = profile_.topology == MathTopology::kPairs ? EvaluatePairs(params, sources)
                                                             : EvaluateChain(params, sources);
  result_ = std::clamp(r, 0.0, 1.0);  // "saturate the output result" (§1.9)
  out.value =
      std::round(params.output_scaling1 + result_ * (params.output_scaling2 - params.output_scaling1));
  output_ = out;
  return output_;
}

}  // namespace canfleet::devices::blocks
