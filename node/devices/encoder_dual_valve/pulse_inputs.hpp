#pragma once
/// @file The two inputs of the AX023241 (1.2, 1.2.1-1.2.3, C3-1.3.1-1.3.16, C3-1.4.1-1.4.6,
/// C3-1.4.46-1.4.49): together a quadrature encoder, or each a frequency, PWM or digital input.
///
/// What an input measures (README.md "Input types"):
///   6112h = 0                        off: 7100h = 0
///   6110h = 10002 (6112h 1 or 10)    quadrature: 2100h 0 count, 1 direction, 2 speed (rpm), from
///                                    the pair (quadrature.hpp); both inputs must be 10002, else 0
///   6110h = 60, 6112h = 1            frequency in Hz x 10^2102h, 0 below the range's lowest
///                                    frequency (Table 3: 0.5 / 10 / 100 Hz; no edge in the window)
///   6110h = 10000, 6112h = 1         duty cycle in % x 10^2102h, 0 outside the range's frequency
///                                    band (Table 3: low < 1 kHz, high > 100 Hz)
///   6110h = 60/10000, 6112h = 10     digital (Table 3 "Digital" column): 2100h 0 normal, 1 inverse,
///                                    2 latched (each OFF->ON of the pin toggles); a floating pin
///                                    reads 1 with the 1 kOhm pull-up (2020h = 1), else 0 (1.2.2)
/// The value (saturated to INTEGER16) runs through the filter 61A0h/61A1h (one call per ms,
/// blocks/input_filter.hpp) into 7100h, the span check 2110h-2112h (blocks/span_monitor.hpp) and
/// the line (7120h,7121h)-(7122h,7123h) into 7130h. 6000h holds one bit per digital input (XOR
/// 6002h); change-of-state TPDOs hear it.
///
/// Time is events: a value that moves with time while nothing else changes (a quadrature count
/// while the shaft turns) is sampled when 7100h/7130h are read (SDO, TPDO) and on the device's
/// evaluations; it keeps the device ticking every millisecond only while something consumes it
/// (a block wired to it, its filter, its span check).
///
/// Faults: out of span after 2112h ms -> EMCY F001h, 1003h 20nnF001h (above 7149h) or 40nnF001h
/// (below 7148h), nn = input, 1029h sub 3; the input is then in error as a control source.

#include <array>
#include <chrono>
#include <memory>
#include <optional>

#include "clock/scheduler.hpp"
#include "node/canopen/stack/canopen_stack.hpp"
#include "node/devices/blocks/input_filter.hpp"
#include "node/devices/blocks/signal.hpp"
#include "node/devices/blocks/span_monitor.hpp"
#include "node/devices/delayed_fault.hpp"
#include "node/devices/encoder_dual_valve/encoder_io.hpp"
#include "node/devices/encoder_dual_valve/quadrature.hpp"
#include "node/devices/od_ref.hpp"

namespace canfleet::devices::encoder {

enum class InputMode : std::uint8_t { kOff, kQuadrature, kFrequency, kPwm, kDigital };

class PulseInputs {
 public:
  using Ms = std::chrono::milliseconds;

  PulseInputs(canopen::CanopenStack& stack, Scheduler& scheduler, EncoderIo& io);
  PulseInputs(const PulseInputs&) = delete;
  PulseInputs& operator=(const PulseInputs&) = delete;

  /// A simulated input changed: the shaft follows the ENC.* signals (and IN1/IN2 frequencies in
  /// `channels` drive) from `now` on.
  void OnSignal(const IoSignal& signal, TimePoint now);

  /// One evaluation at `now`, `elapsed` after the previous one.
  void Update(TimePoint now, Ms elapsed);

  /// 7100h/7130h of `ch` at `now` for a reader: an unfiltered value that moves with the shaft is
  /// sampled now (the others are as of the last evaluation).
  void SampleOnRead(int ch, TimePoint now);

  /// Input `ch` as a control source (Table 6 "Quadrature Encoder Input Measured"): 7100h with
  /// limits 7120h..7122h, in error while its span fault is active.
  blocks::Signal AsSource(int ch) const;

  /// How long until another evaluation can change something with the inputs as they are: 1 ms
  /// while a filter settles or a moving value is consumed (`consumed[ch]`: a block reads input
  /// ch), the rest of a span delay, nullopt when nothing would change.
  std::optional<Ms> NextChange(const std::array<bool, kInputs>& consumed) const;

  InputMode Mode(int ch) const;
  /// Why the present configuration (6110h, 6112h, ENC.drive) does not read `input`; "" when it
  /// does or the signal is not an input's (the simulated I/O's ignored hook).
  std::string IgnoredInput(const IoSignal& input) const;
  /// Power-on / reset node: filters and span flags cleared, the step counter zeroed.
  void Reset(TimePoint now);
  /// 6110h or 2100h was written: the step counter starts again from 0 (quadrature.hpp).
  void ZeroCounter(TimePoint now) { counter_.Zero(shaft_.EdgesAt(now)); }

  const Shaft& shaft() const { return shaft_; }
  std::int32_t Steps(TimePoint now) const { return counter_.Steps(shaft_.EdgesAt(now)); }

 private:
  struct Refs {
    OdRef sensor_type, mode, range, fv_digits, pull, filter_type, filter_constant;
    OdRef error_enable, hysteresis, delay, span_start, span_end;
    OdRef scaling1_fv, scaling1_pv, scaling2_fv, scaling2_pv, field_value, process_value;
  };
  struct Channel {
    blocks::InputFilter filter;
    blocks::SpanMonitor span;
    double fv = 0.0;
    bool settled = true;
    bool was_busy = false;
    bool digital = false;        ///< the digital state after inverse/latched
    bool pin_before = false;     ///< for the latched response
    std::int64_t response = -1;  ///< 2100h as last seen in digital mode (a new response starts OFF)
    std::unique_ptr<DelayedFault> high;
    std::unique_ptr<DelayedFault> low;
  };

  QuadratureParams Quadrature() const;
  bool PairIsQuadrature() const;
  /// The value the input measures now, in field-value units, saturated to INTEGER16.
  double Measured(int ch, TimePoint now) const;
  /// Whether the measured value of `ch` changes with time alone.
  bool Moving(int ch) const;
  bool PinHigh(int ch) const;
  void UpdateDigital(int ch);
  blocks::FilterParams Filter(int ch) const;
  blocks::SpanParams Span(int ch) const;
  void Publish(int ch);
  void UpdateVelocity(TimePoint now);

  canopen::CanopenStack& stack_;
  EncoderIo& io_;
  std::array<Refs, kInputs> refs_;
  std::array<Channel, kInputs> channels_;
  OdRef read_state_, polarity_, qd_scaler_, qd_direction_, qd_offset_, qd_pulses_;
  Shaft shaft_;
  StepCounter counter_;
  /// Direction of the last movement (true = forward); none yet after power-on.
  std::optional<bool> last_forward_;
};

}  // namespace canfleet::devices::encoder
