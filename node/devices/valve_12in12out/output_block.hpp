#pragma once
/// @file The valve's twelve outputs OUT1-OUT8 and DO1-DO4 (UMAX020411A §1.4 digital output block,
/// §1.5 analog output block, §3.3.16-3.3.29, §3.4.19-3.4.48).
///
/// Each output has three inputs wired by (source, number): control 2340h/2341h, enable
/// 2350h/2351h, override 2360h/2361h (Table 15/16; source 0 or an invalid pair = not used). One run
/// decides, in this order (§1.4 a-c, §1.5; Figure 12 is lost):
///   1. NMT stopped, or a supply fault (§4: "hardware shutdown"): off (choices, README.md).
///   2. fault reaction: any input in use reports an error -> 6340h (analog types: 0 hold the FV,
///      1 apply 7341h) / 6250h (digital types: 0 hold the drive state, 1 apply 6260h).
///   3. override: 2362h 0 = while the override input is ON, 1 = while it is OFF -> 2300h.
///   4. enable: 2352h 0-2 enabled while ON, 3-5 while OFF; otherwise 0/3 shut off, 1/4 ramp off
///      (ramp down to 0), 2/5 keep the last value. An enable input not used always enables.
///   5. control: analog types: the Figure 11 line with the 2342h response (output_math.hpp), ramped
///      by 2330h/2331h; digital types: the logic state through 2210h (normal with the 2224h/2225h
///      delay, inverse, latched, blink every 2223h; hotshot outputs blink as normal).
/// Ramps act on the control path only (§1.5 "under normal conditions"); fault, override and shut
/// off apply at once. ON/OFF of enable and override inputs: valve_sources.hpp IsOn().
///
/// 7330h: the driven FV with ramps (analog types), the logic state (digital types). 2370h: averaged
/// over 2371h 1 ms samples (output_math.hpp) of the measured current (current type), the FV
/// (voltage, PWM) or the drive state (digital, hotshot). FVs are in the type's unit (Table 14: mA,
/// mV, % of duty) with 6332h decimals.
///
/// Open/short detection (2310h-2312h, §1.5): current type: |7330h - 2370h| > 2311h, or a short
/// while driven; voltage and PWM: a short while driven ("a signal is also sent to the processor
/// whenever a short has occurred"); digital and hotshot: open or short load while driven ON (the
/// outputs' load monitoring, §4). Held for 2312h on OUT1-OUT7: 10nnF002h, EMCY F002h, 1029h sub 5
/// for analog types and sub 4 for digital types (README.md; §1.5's "Input Fault" sub-index is a
/// slip). OUT8 and DO1-DO4 have no EMCY (Table 33).
///
/// Time: ramps run every millisecond while they move; a delay, a blink, a hotshot or a feedback
/// window in progress wake the node when they are due (NextWake); nothing runs while steady.

#include <array>
#include <chrono>
#include <memory>
#include <optional>

#include "clock/scheduler.hpp"
#include "node/canopen/stack/canopen_stack.hpp"
#include "node/devices/delayed_fault.hpp"
#include "node/devices/od_ref.hpp"
#include "node/devices/valve_12in12out/output_math.hpp"
#include "node/devices/valve_12in12out/valve_io.hpp"
#include "node/devices/valve_12in12out/valve_sources.hpp"

namespace canfleet::devices::valve {

struct OutputConditions {
  bool stopped = false;       ///< NMT stopped
  bool supply_fault = false;  ///< supply under/over voltage active
};

class OutputBlock {
 public:
  OutputBlock(canopen::CanopenStack& stack, Scheduler& scheduler, ValveIo& io, const ValveSources& sources);
  OutputBlock(const OutputBlock&) = delete;
  OutputBlock& operator=(const OutputBlock&) = delete;

  /// One run at `now`, `elapsed` (> 0) after the previous. Returns true if a 7330h or 2370h value
  /// (a control source) changed.
  bool Run(TimePoint now, std::chrono::milliseconds elapsed, const OutputConditions& conditions);
  /// Time from `now` until an output needs the next run.
  std::optional<std::chrono::milliseconds> NextWake(TimePoint now) const;
  /// Reset application: outputs off, timers and faults cleared.
  void Reset();

 private:
  struct Refs {
    OdRef type, control_source, control_number, response, enable_source, enable_number, enable_response,
        override_source, override_number, override_response, override_fv, s1_pv, s1_fv, s2_pv, s2_fv,
        fv_digits, fault_mode, fault_fv, do_fault_mode, do_fault_state, ramp_up, ramp_down, error_enable,
        error_tolerance, error_delay, samples, commanded, feedback, polarity, hotshot_current, hold_current,
        hotshot_time, blink_rate, delay_time, delay_polarity;
  };
  struct Channel {
    std::int64_t type = -1;
    // Analog types.
    double present = 0;  ///< FV driven now (7330h before rounding)
    bool ramping = false;
    // Digital types.
    bool drive = false;
    bool on_control = false;  ///< the control path decided the drive state last run
    bool logic_prev = false;
    bool control_drive = false;  ///< normal polarity: the state after the delay
    std::optional<TimePoint> delay_deadline;
    bool delay_target = false;
    bool latched = false;
    std::optional<TimePoint> blink_start;
    TimePoint on_since{};
    // Feedback.
    FeedbackAverager feedback;
    double sample = 0;  ///< the last run's 1 ms sample
    bool has_sample = false;
    std::unique_ptr<DelayedFault> analog_fault, digital_fault;
  };

  OutputScaling Scaling(int ch) const;
  void RunAnalog(int ch, std::chrono::milliseconds elapsed, const OutputConditions& conditions);
  void RunDigital(int ch, TimePoint now, const OutputConditions& conditions);
  bool ControlDrive(int ch, TimePoint now, bool logic);
  void Publish(int ch, TimePoint now);
  void StartOver(Channel& c);

  ValveIo& io_;
  const ValveSources& sources_;
  OdRef dither_frequency_, dither_amplitude_;
  std::array<Refs, kOutputs> refs_;
  std::array<Channel, kOutputs> channels_;
};

}  // namespace canfleet::devices::valve
