#pragma once
/// @file A function-block output as the Axiomatic family sees it when another block reads it.
///
/// The valve (UMAX020411A §1.5 Tables 15-17), encoder (AX023241 §1.3 Tables 6-7, §1.4) and data
/// logger (UMAX181001 §1.4 Tables 13-15) wire blocks by (source, number) and the consumer
/// normalises what it reads with the producer's limits ("Scaling 1" / "Scaling 2" of Table 17).
/// A Signal therefore carries the value together with those limits:
/// - `value`, `min`, `max` are in the producer's object units (the integer an SDO upload of
///   7100h, 3yz8h, 4030h, 2460h ... returns; a constant 5010h is its float). Logic conditions
///   compare these raw values ("constants in the resolution of argument 1", valve §1.8.1).
/// - `decimal_digits` says how to turn them into engineering units (Table 17 "Dec Digits");
///   math inputs need it because their own scaling objects carry their own digits (§1.9).
/// - `has_range` is false for sources whose limits Table 17 gives as "N/A" (constants, supply,
///   temperature); a PID then borrows the feedback's limits (valve §1.6).
/// - `error`: "input faulted" (an analog input out of span after its delay, a block fed by one).
/// - `available`: false for "Control Source Not Used" and for a lookup table without an X-axis
///   source (valve §1.8.3 "Not Available"); logic conditions turn it into N/A (Table 26).
///
/// Tick order (all blocks of a product, every tick; valve §1.7-1.9 say nothing, so this is a
/// choice made once for the family, README.md): inputs (AI/DI filters, span faults, received
/// PDO values) -> math -> lookup tables -> logic -> PID -> outputs. Math comes before the lookup
/// tables because the manuals' own example drives a table from a math block (encoder §1.6.4);
/// tables come before logic because a logic block outputs its selected table (valve §1.8.3).
/// Loop rule: a block that reads its own output, or a block later in that order, reads the
/// value of the previous tick (nothing is evaluated twice in one tick).

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace canfleet::devices::blocks {

struct Signal {
  double value = 0.0;
  /// Scaling 1 / Scaling 2 of Table 17: the producer's limits in the units of `value`.
  double min = 0.0;
  double max = 100.0;
  bool has_range = true;
  std::uint8_t decimal_digits = 0;
  bool error = false;
  bool available = true;

  /// `value` as 0..100 % of [min, max], held at the ends like every consumer in the family
  /// (valve Figure 11: "held at S1FV/S2FV outside"). A signal without range is taken as a
  /// percentage already; an empty range (min == max) gives 0.
  double ToPercent() const {
    if (!has_range) return std::clamp(value, 0.0, 100.0);
    return PercentOf(value, min, max);
  }

  /// `v` as 0..100 % of [lo, hi] (clamped); lo > hi is an inverse range; lo == hi gives 0.
  static double PercentOf(double v, double lo, double hi) {
    if (hi == lo) return 0.0;
    return std::clamp((v - lo) / (hi - lo) * 100.0, 0.0, 100.0);
  }

  /// "Control Source Not Used": no value, no error.
  static Signal NotAvailable() {
    Signal s;
    s.available = false;
    return s;
  }

  /// A 5010h constant: a float without limits (Table 17 "N/A (float)").
  static Signal Constant(double v) {
    Signal s;
    s.value = v;
    s.has_range = false;
    return s;
  }

  /// A 0..100 % block output stored with `digits` decimals and rounded like its INTEGER16 object
  /// (PID 2460h and logic 3320h: 1 digit, so 0..1000; Table 17 "0% / 100% / 1 (fixed)").
  static Signal Percent(double percent, std::uint8_t digits = 1);
};

/// 10^digits as a double (digits beyond 9 are not used by any object of the family).
inline double PowerOfTen(std::uint8_t digits) {
  double p = 1.0;
  for (std::uint8_t i = 0; i < digits; ++i)
    p *= 10.0;
  return p;
}

inline Signal Signal::Percent(double percent, std::uint8_t digits) {
  const double scale = PowerOfTen(digits);
  Signal s;
  s.value = std::round(percent * scale);
  s.min = 0.0;
  s.max = 100.0 * scale;
  s.decimal_digits = digits;
  return s;
}

}  // namespace canfleet::devices::blocks
