#pragma once
/// @file The family PID block (valve UMAX020411A §1.6 Figure 14, §3.3.32-3.3.35, §3.4.49-3.4.57;
/// encoder AX023241 §1.8 Table 14).
///
/// Every cycle (7456h), with target and feedback normalised to % of their sources' limits (a
/// source without limits, e.g. a constant, borrows the feedback's; valve §1.6):
///   E = target% - feedback%, E = 0 if |E| < tolerance (2450h)
///   S += E
///   out = E*Pg + S*Ig + (E - E_prev)*Dg
/// valve:   T = cycle [s], Pg = G, Ig = G*Ki*T/Ti, Dg = G*Kd*Td/T
/// encoder: T = 0.001 s fixed, Pg = G, Ig = Ki*T/Ti, Dg = Kd*Td/T (G does not scale I and D)
/// Ig = 0 if Ti = 0 (both). The manuals do not say how the output is limited beyond "a value
/// between 0 to 100%" (valve §3.4.57); choices (README.md):
/// - single output / setpoint control: out clamped to 0..100 %.
/// - push-pull ("on when over target", "on when below target"): the loop runs on -100..100 % and
///   each response shows its half: below = max(0, out), over = max(0, -out).
/// - anti-windup by conditional integration: when out would pass a limit and E pushes further
///   that way, S takes only the part of this cycle's E that brings out to the limit (none if P
///   and D alone are past it), so the output leaves the limit as soon as E changes sign.
/// - not enabled (a source "not used"): output 0, state reset. A faulted target or feedback:
///   the output holds its last value with the error flag set, and the state does not move.
///
/// Tick order and loop rule: see signal.hpp (inputs -> math -> LUT -> logic -> PID -> outputs; a
/// block reading itself or a later block sees the previous tick).

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>

#include "node/devices/blocks/signal.hpp"

namespace canfleet::devices::blocks {

enum class PidResponse : std::uint8_t {
  kSingleOutput,
  kSetpointControl,
  kOnWhenOverTarget,
  kOnWhenBelowTarget
};

/// The per-product facts of the block.
struct PidProfile {
  /// Valve: Ig and Dg are multiplied by G; encoder: they are not.
  bool gain_scales_integral_and_derivative = true;
  /// T of the formula: nullopt = the cycle time (valve), else fixed (encoder: 0.001 s).
  std::optional<std::chrono::duration<double>> formula_period;
  /// 2457h value -> response (nullopt = value not allowed).
  std::array<std::optional<PidResponse>, 4> response_codes{PidResponse::kSingleOutput,
                                                           PidResponse::kOnWhenOverTarget,
                                                           PidResponse::kOnWhenBelowTarget, std::nullopt};

  std::optional<PidResponse> DecodeResponse(std::uint8_t code) const {
    return code < response_codes.size() ? response_codes[code] : std::nullopt;
  }
};

/// Valve Table 22: 0 single output, 1 on when over target, 2 on when below target.
PidProfile ValvePidProfile();
/// Encoder Table 14: 0 single, 1 setpoint control, 2 on when over, 3 on when below; T = 0.001 s.
PidProfile EncoderPidProfile();

/// The block's configuration in engineering units (the product converts its objects: 7450h,
/// 2451h, 2452h and 2450h have 1 decimal; 7452h/7454h/7456h are seconds with 6459h decimals).
struct PidParams {
  double gain = 0.5;                                  ///< G, 7450h (5 = 0.5)
  double ki = 1.0;                                    ///< 2451h (10 = 1.0)
  double kd = 1.0;                                    ///< 2452h (10 = 1.0)
  std::chrono::duration<double, std::milli> ti{5.0};  ///< 7452h
  std::chrono::duration<double, std::milli> td{1.0};  ///< 7454h
  std::chrono::milliseconds cycle{10};                ///< 7456h
  double tolerance_percent = 1.0;                     ///< 2450h (10 = 1.0 %)
  PidResponse response = PidResponse::kSingleOutput;
};

struct PidGains {
  double p = 0.0;
  double i = 0.0;
  double d = 0.0;
};

/// Pg, Ig, Dg of Figure 14 (valve) / §1.8 (encoder).
PidGains ComputePidGains(const PidParams& params, const PidProfile& profile);

class Pid {
 public:
  explicit Pid(PidProfile profile = ValvePidProfile()) : profile_(profile) {}

  /// Advances time by `elapsed` and runs one cycle per full 7456h period that has passed, each
  /// with these inputs. Returns the output (as Output()).
  const Signal& Tick(std::chrono::milliseconds elapsed, const PidParams& params, const Signal& target,
                     const Signal& feedback);
  /// Runs exactly one cycle now.
  const Signal& Step(const PidParams& params, const Signal& target, const Signal& feedback);

  /// 2460h: 0..1000 (0.1 %), limits 0..1000, 1 digit (Table 17); error = a faulted input.
  const Signal& Output() const { return output_; }
  double OutputPercent() const { return output_percent_; }
  /// The last (deadbanded) error in %, and the error sum S.
  double Error() const { return error_; }
  double ErrorSum() const { return error_sum_; }
  bool Enabled() const { return enabled_; }

  /// Whether another cycle with the same inputs can change the output: false once the loop is
  /// disabled, or has had E = 0 for two cycles in a row (P, I and D terms all constant).
  bool Busy() const;
  /// Time until the next cycle runs.
  std::chrono::milliseconds NextStepAfter(const PidParams& params) const;

  /// Power-up state: S = 0, E_prev = 0, output 0.
  void Reset();

 private:
  PidProfile profile_;
  Signal output_ = Signal::Percent(0.0);
  double output_percent_ = 0.0;
  double error_ = 0.0;
  double previous_error_ = 0.0;
  double error_sum_ = 0.0;
  bool enabled_ = false;
  bool settled_ = false;
  std::chrono::milliseconds since_step_{0};
};

}  // namespace canfleet::devices::blocks
