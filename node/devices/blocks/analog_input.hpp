#pragma once
/// @file The universal analog input chain (valve UMAX020411A §1.3 Figure 6, §3.3.3-3.3.15,
/// §3.4.4-3.4.18; logger UMAX181001 §1.4; encoder AX023241 §1.2, §1.2.3 for its pulse inputs).
///
///   measured (base unit: V, mA, 0.01 kOhm is kOhm x 100 ..., Hz, rpm, %) x 10^2102h
///     -> filter 61A0h/61A1h, one call per ms (input_filter.hpp)
///     -> round -> 7100h field value -> span check 2110h-2112h, 7148h/7149h (span_monitor.hpp)
///     -> PV = S1PV + (FV - S1FV)(S2PV - S1PV)/(S2FV - S1FV) -> 7130h process value (rounded)
/// The shift comes before the filter here (both are linear; the manual shifts after): the filter
/// then works in the field value's resolution, which is what the third-order filter's "16-bit
/// fixed point" implies. S1FV == S2FV (a degenerate line) gives PV = FV. The PV is not held to
/// the scaling points (the manual's Figure 7 is lost). As a control source the input is its FV
/// with limits 7120h..7122h and 2102h digits (Table 17), in error while the span fault is active.
///
/// Time: Tick(elapsed) runs one filter call and one span check per millisecond of `elapsed`
/// with the same measured value (the product samples its pins at its own rate, the valve every
/// 10 ms, §4). Once the filter has settled and no fault delay is counting, the rest of the tick
/// is skipped; Busy() tells the caller it may stop ticking until the measured value changes.
///
/// Tick order and loop rule: see signal.hpp (inputs -> math -> LUT -> logic -> PID -> outputs; a
/// block reading itself or a later block sees the previous tick).

#include <chrono>
#include <cstdint>

#include "node/devices/blocks/input_filter.hpp"
#include "node/devices/blocks/signal.hpp"
#include "node/devices/blocks/span_monitor.hpp"

namespace canfleet::devices::blocks {

struct AnalogInputParams {
  FilterParams filter;
  /// 2102h: field value = measured x 10^digits.
  std::uint8_t fv_digits = 3;
  /// 7120h-7123h (defaults: 0-5 V, PV = FV).
  double scaling1_fv = 500;
  double scaling1_pv = 500;
  double scaling2_fv = 4500;
  double scaling2_pv = 4500;
  SpanParams span;
};

class AnalogInput {
 public:
  /// Advances by `elapsed` with the pin measuring `measured` (base units).
  void Tick(std::chrono::milliseconds elapsed, const AnalogInputParams& params, double measured);

  /// 7100h.
  double FieldValue() const { return fv_; }
  /// 7130h.
  double ProcessValue() const { return pv_; }
  SpanFlag Flag() const { return span_.Flag(); }
  bool Faulted() const { return span_.Faulted(); }
  const SpanMonitor& span() const { return span_; }
  const InputFilter& filter() const { return filter_; }

  /// The input as a control source (Table 17: FV, 7120h..7122h, 2102h digits).
  Signal AsSource(const AnalogInputParams& params) const;

  /// Whether more ticks with the same measured value can change anything: the filter has not
  /// settled, or a span flag is waiting for its delay.
  bool Busy() const { return !settled_ || span_.Busy(); }

  /// Power-up: filter from 0, no flags.
  void Reset();

 private:
  void UpdateProcessValue(const AnalogInputParams& params);

  InputFilter filter_;
  SpanMonitor span_;
  double fv_ = 0.0;
  double pv_ = 0.0;
  bool settled_ = false;
};

/// PV of `fv` through (S1FV, S1PV), (S2FV, S2PV), unrounded.
double ScaleToProcessValue(const AnalogInputParams& params, double fv);

}  // namespace canfleet::devices::blocks
