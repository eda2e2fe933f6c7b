#pragma once
/// @file The math block (valve UMAX020411A §1.9 Table 30, §3.4.85-3.4.97; logger UMAX181001 §1.7
/// Table 23; encoder AX023241 §1.7 Table 13).
///
/// Each input is read through its source and made a fraction (1.0 = 100 %) of its own scaling
/// objects (4y20h..4y22h with 4y03h decimals), held to 0..1, then multiplied by its gain
/// (4y40h, -1.0..1.0). Functions combine two fractions with an operator (4y50h):
/// - comparisons and logic give 0 or 1; a logic operand is TRUE when >= the product's threshold
///   (valve/logger 0.5, encoder 1);
/// - arithmetic: "/" by 0 gives the product's value (valve/logger 0, encoder 100 % = 1); valve/
///   logger "-" below 0 gives 0; the encoder saturates every function to 0..100 %.
/// Topology (per product):
/// - pairs (valve, logger): F1 = In1 op In2, F2 = In3 op In4, F3 = In5 op In6; a function with an
///   unused input is ignored; the block result is the last function not ignored ("the result of
///   the Math Block will be the result of Function 3"). An input whose source is this math block
///   and whose 4y02h function number is 1..3 reads that function's result (this tick's if that
///   function has already run, else the previous tick's), times its gain.
/// - chain (encoder): ((((In1 op1 In2) op2 In3) op3 In4) op4 In5); an unused operand B passes the
///   running result through.
/// Faulted inputs count as 0.0 and the output carries no error (valve §1.9 "Error data ... is
/// always treated as a 0.0 input"). The result is held to 0..1 and scaled to the output limits:
/// 4030h = 4021h + result x (4023h - 4021h), rounded. Disabled (4000h FALSE): output 0.
///
/// Tick order and loop rule: see signal.hpp (inputs -> math -> LUT -> logic -> PID -> outputs; a
/// block reading itself or a later block sees the previous tick).

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "node/devices/blocks/control_source.hpp"
#include "node/devices/blocks/signal.hpp"

namespace canfleet::devices::blocks {

enum class MathOp : std::uint8_t {
  kEqual,
  kNotEqual,
  kGreater,
  kGreaterOrEqual,
  kLess,
  kLessOrEqual,
  kOr,
  kNor,
  kAnd,
  kNand,
  kXor,
  kXnor,
  kAdd,
  kSubtract,
  kMultiply,
  kDivide,
  kMin,
  kMax,
  kMaxMinusMin,  ///< encoder only
};

enum class MathTopology : std::uint8_t { kPairs, kChain };

/// The per-product facts of the block.
struct MathProfile {
  /// 4y50h value -> operator; values past the end are not allowed.
  std::span<const MathOp> operators;
  MathTopology topology = MathTopology::kPairs;
  std::size_t inputs = 6;
  double logic_true_threshold = 0.5;
  double divide_by_zero = 0.0;
  bool negative_difference_is_zero = true;
  bool saturate_each_function = false;

  std::optional<MathOp> DecodeOperator(std::uint8_t code) const {
    return code < operators.size() ? std::optional<MathOp>(operators[code]) : std::nullopt;
  }
  /// Functions per block: pairs = inputs / 2, chain = inputs - 1.
  std::size_t Functions() const { return topology == MathTopology::kPairs ? inputs / 2 : inputs - 1; }
};

/// Valve Table 30: 0-5 comparisons, 6-11 OR NOR AND NAND XOR XNOR, 12-17 + - x / MIN MAX.
MathProfile ValveMathProfile();
/// Logger Table 23: the valve's operators in the same order (the value column is damaged).
MathProfile DataLoggerMathProfile();
/// Encoder Table 13: 0-5 comparisons, 6 OR, 7 AND, 8 XOR, 9-15 + - x / MIN MAX MAX-MIN; five
/// inputs in a chain, logic TRUE at >= 1, "/" by 0 = 100 %, functions saturate at 0..100 %.
MathProfile EncoderMathProfile();

struct MathInputParams {
  SourceRef source;
  /// 4y02h: 1..3 = read that function of this block (with source = math, number = this block).
  std::uint8_t function = 0;
  /// 4y20h / 4y22h with 4y03h decimals.
  double scaling1 = 0.0;
  double scaling2 = 10000.0;
  std::uint8_t decimal_digits = 2;
  /// 4y40h / 100.
  double gain = 1.0;
};

struct MathBlockParams {
  bool enabled = false;
  std::vector<MathInputParams> inputs;
  /// 4y50h values, one per function.
  std::vector<std::uint8_t> operators;
  /// 4021h / 4023h with 4032h decimals.
  double output_scaling1 = 0.0;
  double output_scaling2 = 10000.0;
  std::uint8_t output_digits = 2;
};

/// Defaults of §3.4.85-3.4.97: all inputs not used, gain 1.0, scaling 0..10000 (2 digits),
/// operators "+", output 0..10000 (2 digits), disabled.
MathBlockParams DefaultMathBlockParams(const MathProfile& profile);

/// One operator on two fractions, with the profile's rules.
double ApplyMathOp(MathOp op, double a, double b, const MathProfile& profile);

class MathBlock {
 public:
  /// @param own_number this block's number as a source (1..6), for 4y02h chaining.
  MathBlock(MathProfile profile, std::uint8_t own_number) : profile_(profile), own_number_(own_number) {}

  /// Evaluates one tick.
  const Signal& Update(const MathBlockParams& params, const ControlSources& sources);

  /// 4030h with limits 4021h..4023h and 4032h digits (Table 17).
  const Signal& Output() const { return output_; }
  /// The block result as a fraction before output scaling (0..1).
  double Result() const { return result_; }
  /// Function k's result of the last tick (nullopt = ignored).
  std::optional<double> FunctionResult(std::size_t k) const {
    return k < functions_.size() ? functions_[k] : std::nullopt;
  }

 private:
  double ReadInput(const MathInputParams& input, const ControlSources& sources) const;
  double EvaluatePairs(const MathBlockParams& params, const ControlSources& sources);
  double EvaluateChain(const MathBlockParams& params, const ControlSources& sources);

  MathProfile profile_;
  std::uint8_t own_number_;
  Signal output_ = Signal::Percent(0.0, 2);
  double result_ = 0.0;
  std::array<std::optional<double>, 8> functions_{};
};

}  // namespace canfleet::devices::blocks
