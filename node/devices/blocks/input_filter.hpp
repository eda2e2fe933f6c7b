#pragma once
/// @file The software filter of an analog input (61A0h type, 61A1h constant; valve UMAX020411A
/// §1.3 Table 8, logger UMAX181001 §1.4 Table 9, encoder AX023241 §1.2.3 Table 5).
///
/// One Step() is one call of the manual's filter routine, "called every 1ms":
/// - 0 none: V = In.
/// - 1 moving average: V += (In - V) / C (C = 61A1h).
/// - 2 repeating average: In is added to a sum; every C-th call V = sum / C and the sum restarts;
///   V holds in between (encoder Equation 2 "will remain until the next average is ready").
/// - 3 third-order low pass (valve/logger only), run every C-th call in 16-bit fixed point:
///   V[n] = (N0 In[n] + N1 In[n-1] + N2 In[n-2] + N3 In[n-3] + O1 V[n-1] + O2 V[n-2] + O3 V[n-3])
///   >> P, on integers (2120h P = 10, 2121h-2124h N0-N3 = 120, 241, 120, 0, 2125h-2127h O1-O3 =
///   704, -164, 0). The defaults have a DC gain of 481 / 484: a settled output sits 0.6 % low.
/// The filter runs in field-value units (after the 2102h shift; both are linear, only the third-
/// order filter rounds its input to whole units first). It starts from 0 (the manual resets the
/// repeating average's value and counter to zero). A moving average closer to its input than
/// 0.001 field-value units snaps onto it, so "settled" is reached in finite time.
///
/// Tick order and loop rule: see signal.hpp (inputs -> math -> LUT -> logic -> PID -> outputs; a
/// block reading itself or a later block sees the previous tick).

#include <array>
#include <cstdint>
#include <optional>

namespace canfleet::devices::blocks {

enum class FilterType : std::uint8_t { kNone, kMovingAverage, kRepeatingAverage, kThirdOrderLowPass };

/// 61A0h value -> filter if the product has it (valve/logger 0-3; encoder 0-2: `third_order` false).
std::optional<FilterType> DecodeFilterType(std::uint8_t code, bool third_order);

struct ThirdOrderCoefficients {
  std::array<std::int32_t, 4> input{120, 241, 120, 0};  ///< N0-N3, 2121h-2124h
  std::array<std::int32_t, 3> output{704, -164, 0};     ///< O1-O3, 2125h-2127h
  std::uint8_t power = 10;                              ///< P, 2120h (0..16)
};

struct FilterParams {
  FilterType type = FilterType::kNone;
  /// 61A1h, 1..1000 (0 is read as 1).
  std::uint16_t constant = 10;
  ThirdOrderCoefficients third_order;
};

class InputFilter {
 public:
  /// One filter call with input `in` (field-value units).
  void Step(const FilterParams& params, double in);
  /// The filtered value (unrounded).
  double Value() const { return value_; }
  /// Whether another Step() with the same input and parameters would change nothing.
  bool Settled(const FilterParams& params, double in) const;
  /// Starts over from `value` (history, sum and counters cleared).
  void Reset(double value = 0.0);

 private:
  std::int64_t ThirdOrderNext(const ThirdOrderCoefficients& c, std::int64_t in) const;

  double value_ = 0.0;
  double sum_ = 0.0;
  std::uint32_t count_ = 0;
  std::array<std::int64_t, 3> in_history_{};   ///< In[n-1], In[n-2], In[n-3]
  std::array<std::int64_t, 3> out_history_{};  ///< V[n-1], V[n-2], V[n-3]
};

}  // namespace canfleet::devices::blocks
