#pragma once
/// @file The programmable logic block (valve UMAX020411A §1.8 Tables 24-29, §3.4.71-3.4.84;
/// logger UMAX181001 §1.6 Tables 17-22, the same rules; the encoder lists "programmable logic"
/// as source 7 but documents no objects).
///
/// Three functions A, B, C, each with three conditions and a lookup table number (3x01h):
/// - condition (3xYZh): arg1 (src, num) operator arg2 (src, num), operators 0 = ... 5 <= on the
///   arguments' raw values ("constants in the resolution of argument 1", §1.8.1). Result
///   (Table 26): N/A if either argument is not available ("Control Source Not Used"; checked
///   first, so an unused argument disables the condition even beside a faulted one), else Error
///   if either is faulted, else True/False.
/// - function operator (3x02h, Table 27/28): 0 default table (always true); 1 C1&C2&C3 with N/A as
///   True and False/Error as False; 2 C1|C2|C3, 3 (C1&C2)|C3, 4 (C1|C2)&C3 with Error and N/A as
///   False.
/// - selection (Figure 19): A, then B, then C; the first true function wins and later ones are
///   not evaluated; none true -> A.
/// - output (§1.8.3): the selected table's output as 0..100 % of its Y range, 0.1 % (3320h);
///   "Not Available" if that table has no X-axis source; its error flag passes through.
/// A disabled block (3300h FALSE) selects nothing (3310h = 0) and is not available.
///
/// Tick order and loop rule: see signal.hpp (inputs -> math -> LUT -> logic -> PID -> outputs; a
/// block reading itself or a later block sees the previous tick).

#include <array>
#include <cstdint>
#include <optional>

#include "node/devices/blocks/control_source.hpp"
#include "node/devices/blocks/signal.hpp"

namespace canfleet::devices::blocks {

/// Table 25.
enum class CompareOp : std::uint8_t { kEqual, kNotEqual, kGreater, kGreaterOrEqual, kLess, kLessOrEqual };
/// Table 26.
enum class ConditionResult : std::uint8_t { kFalse, kTrue, kError, kNotApplicable };
/// Table 27.
enum class FunctionOperator : std::uint8_t {
  kDefaultTable,
  kAllTrue,
  kAnyTrue,
  kFirstTwoOrThird,
  kEitherOfTwoAndThird
};

/// Table 25 / Table 27 object values; nullopt = not allowed (SDO validators).
std::optional<CompareOp> DecodeCompareOp(std::uint8_t code);
std::optional<FunctionOperator> DecodeFunctionOperator(std::uint8_t code);

struct LogicCondition {
  SourceRef arg1;
  SourceRef arg2;
  CompareOp op = CompareOp::kEqual;
};

struct LogicFunction {
  std::array<LogicCondition, 3> conditions;
  FunctionOperator op = FunctionOperator::kAllTrue;
  /// 3x01h: the lookup table (1..12) this function selects.
  std::uint8_t table = 0;
};

struct LogicBlockParams {
  bool enabled = false;
  std::array<LogicFunction, 3> functions;
};

/// Defaults of logic block `block` (1..4): tables 3b-2, 3b-1, 3b (Table 29), operators A and B
/// "Cnd1 And Cnd2 And Cnd3", C "Default Table" (§1.8.2), conditions "not used" (§1.8.1).
LogicBlockParams DefaultLogicBlockParams(std::uint8_t block);

/// Table 26 for one condition.
ConditionResult EvaluateCondition(const LogicCondition& condition, const ControlSources& sources);
/// Table 28 for one function.
bool EvaluateFunction(FunctionOperator op, const std::array<ConditionResult, 3>& results);

struct LogicResult {
  /// Condition results of the functions that were evaluated (later ones stay N/A).
  std::array<std::array<ConditionResult, 3>, 3> conditions{};
  /// 0 = A, 1 = B, 2 = C; nullopt when disabled.
  std::optional<std::uint8_t> function;
  /// 3310h: the selected lookup table number (0 when disabled).
  std::uint8_t table = 0;
  /// 3320h.
  Signal output = Signal::NotAvailable();
};

class LogicBlock {
 public:
  /// Evaluates one tick: conditions, selection, and reads the selected table through `sources`
  /// (SourceKind::kLookupTable).
  const LogicResult& Update(const LogicBlockParams& params, const ControlSources& sources);
  const LogicResult& Result() const { return result_; }
  const Signal& Output() const { return result_.output; }

 private:
  LogicResult result_;
};

}  // namespace canfleet::devices::blocks
