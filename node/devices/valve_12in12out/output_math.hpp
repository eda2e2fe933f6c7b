#pragma once
/// @file The pure parts of the valve's output block (UMAX020411A §1.4, §1.5): the PV-to-FV line of
/// Figure 11 with the 2342h responses, the digital reading of a control value, ramps, and the
/// averaged feedback of 2370h/2371h.

#include <chrono>
#include <cstdint>

namespace canfleet::devices::valve {

/// The output scaling 7320h-7323h in raw object units.
struct OutputScaling {
  double s1_pv = 0;  ///< 7320h
  double s1_fv = 0;  ///< 7321h
  double s2_pv = 0;  ///< 7322h
  double s2_fv = 0;  ///< 7323h
};

/// Figure 11 / Table 18: FV = S1FV + (PV - S1PV)(S2FV - S1FV)/(S2PV - S1PV), held at S1FV below S1PV
/// and at S2FV above S2PV; response 1 gives 0 (off) below S1PV, response 2 gives 0 above S2PV. An
/// empty PV span (7320h = 7322h, refused by SDO but possible from a file) steps at S2PV.
double FieldValueOf(double pv, const OutputScaling& s, std::uint8_t response);

/// A digital output's logic state from its control value (§1.4; 2342h is ignored there): ON at
/// or above the middle of 7320h..7322h (a 0/1 command is ON at 1).
bool LogicStateOf(double pv, const OutputScaling& s);

/// One ramp step (§1.5, 2330h/2331h: ms for the whole S1FV..S2FV span; 0 = no ramp): moves
/// `present` toward `target` by `elapsed` worth of the up (FV rising) or down rate.
double RampStep(double present, double target, const OutputScaling& s, std::int64_t ramp_up_ms,
                std::int64_t ramp_down_ms, std::chrono::milliseconds elapsed);

/// 2370h: the output sampled every 1 ms and averaged over 2371h samples, so it changes once per
/// window (§1.5 "updated with new data every 100 ms" at the default 100).
class FeedbackAverager {
 public:
  /// `duration` of samples all equal to `value`, with `samples` per window (1..100).
  void Add(double value, std::int64_t duration_ms, std::int64_t samples);
  /// The last completed average (rounded).
  double Value() const { return value_; }
  /// Milliseconds (>= 1) until the window in progress completes when that can change Value() (the
  /// output moved since); 0 when the feedback already shows `sample` and the window holds only it.
  std::int64_t UntilChange(double sample, std::int64_t samples) const;
  void Reset();

 private:
  double value_ = 0;
  double sum_ = 0;
  std::int64_t count_ = 0;
};

}  // namespace canfleet::devices::valve
