#pragma once
/// @file Out-of-span detection of an analog input (valve UMAX020411A §1.3 after Table 11,
/// §3.4.14-3.4.18; logger UMAX181001 §1.4, the same text; encoder AX023241 §1.2 names 2110h-2112h
/// without the algorithm, so it gets the same one).
///
/// With 2110h enabled, on the field value 7100h:
/// - FV < span start 7148h sets "out of range low"; FV > span end 7149h sets "high". "Both flags
///   cannot be active at once. Setting either one of these flags automatically clears the other."
///   (a switch restarts the delay: it is a new flag).
/// - low clears once FV >= span start + hysteresis 2111h; high once FV <= span end - hysteresis.
/// - a flag that stays set for the reaction delay 2112h (ms) becomes a fault: the EMCY/1003h
///   event of the product (40nnF001h low / 20nnF001h high on the valve) and the input's `error`
///   as a control source. The fault ends when its flag clears.
/// Disabling 2110h clears flag and fault at once.
///
/// Tick order and loop rule: see signal.hpp (inputs -> math -> LUT -> logic -> PID -> outputs; a
/// block reading itself or a later block sees the previous tick).

#include <chrono>
#include <cstdint>

namespace canfleet::devices::blocks {

enum class SpanFlag : std::uint8_t { kNone, kLow, kHigh };

struct SpanParams {
  bool enabled = true;                    ///< 2110h
  double span_start = 200;                ///< 7148h, FV units
  double span_end = 4800;                 ///< 7149h, FV units
  double hysteresis = 100;                ///< 2111h, FV units
  std::chrono::milliseconds delay{1000};  ///< 2112h
};

class SpanMonitor {
 public:
  /// `elapsed` has passed since the previous Update with the flag as it was; `fv` is the field
  /// value now.
  void Update(const SpanParams& params, double fv, std::chrono::milliseconds elapsed);

  SpanFlag Flag() const { return flag_; }
  /// The flag has been held for the delay.
  bool Faulted() const { return faulted_; }
  /// The faulted flag, kNone while not faulted.
  SpanFlag Fault() const { return faulted_ ? flag_ : SpanFlag::kNone; }
  /// A flag is set and its delay is still counting.
  bool Busy() const { return flag_ != SpanFlag::kNone && !faulted_; }
  /// How long the current flag has been set.
  std::chrono::milliseconds Held() const { return held_; }

  void Reset();

 private:
  SpanFlag flag_ = SpanFlag::kNone;
  bool faulted_ = false;
  std::chrono::milliseconds held_{0};
};

}  // namespace canfleet::devices::blocks
