#pragma once
/// @file The data logger's ten inputs (UMAX181001 §1.3, §1.4, §3.3.1, §3.3.4-3.3.16, §3.4.1-3.4.18):
/// seven analog inputs and three universal ones (8-10) that can also be digital.
///
/// 6112h operating mode per input:
/// - 0 Channel Off: 7100h = 7130h = 0, 6020h = 0, no span check.
/// - 1 Normal: the family's analog chain (blocks/analog_input.hpp): measured value in the base
///   unit of 6110h (V, mA, Hz or rpm with 2101h != 0 as Hz x 60 / pulses, PWM %) x 10^2102h ->
///   61A0h/61A1h filter called every 1 ms -> 7100h -> 2110h-2112h span check -> 7130h by
///   7120h-7123h. 6020h = 0 ("For all other operating modes, object 6020h will always be zero").
/// - 10 Digital Input (inputs 8-10): the pin (INn.level; open reads HIGH with the 2020h pull-up,
///   LOW without) through 2010h polarity (Table 4: 0 normal, HIGH = ON; 1 inverse; 2 latched: each
///   LOW->HIGH edge toggles) -> 6020h; 7100h = 6020h (Table 10 "Digital Input 0 [On/Off]"),
///   7130h by 7120h-7123h, no span check. 2030h debounce (111 ns-14 us) is below the simulation's
///   resolution and has no effect.
/// - 20 Analog On/Off (any input): the analog chain runs, and 6020h follows 7100h with hysteresis
///   (Figure 5 is damaged): ON once 7100h >= 7122h (MAX), OFF once 7100h <= 7120h (MIN).
///
/// Span faults (F001h, Table 26: 20ccF001h high, 40ccF001h low, cc = input) are reported on both
/// ports; the 1029h sub 3 reaction applies to inputs 1-7 only (§1.4 "It only applies to the 7
/// Analog Inputs"), inputs 8-10 report without an NMT reaction.
///
/// Time: Advance(elapsed) runs the filters and span delays with the pins as last latched; the
/// device latches the pins (Latch) whenever one changes, after advancing to that moment.

#include <array>
#include <chrono>
#include <memory>
#include <optional>
#include <span>

#include "clock/scheduler.hpp"
#include "node/canopen/stack/canopen_stack.hpp"
#include "node/devices/blocks/analog_input.hpp"
#include "node/devices/blocks/analog_input_defaults.hpp"
#include "node/devices/datalogger_tc_analog/datalogger_io.hpp"
#include "node/devices/datalogger_tc_analog/device_fault.hpp"
#include "node/devices/od_ref.hpp"

namespace canfleet::devices::datalogger {

class AnalogInputBlock {
 public:
  AnalogInputBlock(canopen::ObjectDictionary& od, const DataLoggerIo& io, Scheduler& scheduler,
                   std::span<canopen::CanopenStack* const> stacks);

  /// Copies the pins into the values the filters run on; sees digital edges (latched polarity).
  void Latch();
  /// Runs `elapsed` of filter calls and span delays with the latched pins.
  void Advance(std::chrono::milliseconds elapsed);
  /// Writes 7100h, 7130h, 6020h and the span faults.
  void Publish();

  /// Whether some filter has not settled (the next cycle is one scan later).
  bool Settling() const;
  /// The earliest moment a span flag's delay ends, counted from now (filters settled); nullopt if
  /// no delay is counting.
  std::optional<std::chrono::milliseconds> NextDelayEnd() const;

  /// Control source "Analog Input Function Block" (Table 13-15): 7100h with 7120h..7122h and
  /// 2102h decimals (the FV's own digits; Table 15 prints 6132h, equal by default), in error while
  /// its span fault is active; in modes 10 and 20 the DI state 6020h (0/1).
  blocks::Signal Source(int ch) const;

  /// 6110h, 2100h, 2101h or 6112h of input `ch` was written over the network: Table 11 when the
  /// class changed and 5550h is TRUE (analog_config.hpp). `sensor_type_written`: a 6110h that
  /// differs from the one before first puts 2100h back to 0 and (not frequency/PWM) 2020h to 0.
  void OnConfigWritten(int ch, bool sensor_type_written);
  /// Why the present 6110h/6112h do not read `input`; "" when they do or it is no input pin's
  /// signal (the simulated I/O's ignored hook).
  std::string IgnoredInput(const IoSignal& input) const;
  /// Re-reads every input's class without applying Table 11 (after a reset or restore).
  void RefreshClasses();

  const blocks::AnalogInput& Input(int ch) const { return channels_.at(static_cast<std::size_t>(ch)).ai; }
  const DeviceFault& HighFault(int ch) const { return *channels_.at(static_cast<std::size_t>(ch)).high; }
  const DeviceFault& LowFault(int ch) const { return *channels_.at(static_cast<std::size_t>(ch)).low; }

  /// Reset application: filters from 0, no flags, latched digital states OFF.
  void Reset();
  void ResetPort(std::size_t port);

 private:
  struct Pins {
    double voltage_mv = 0;
    double current_ma = 0;
    double frequency_hz = 0;
    double duty_pct = 0;
    bool level_high = false;
  };
  struct Channel {
    // Configuration.
    OdRef mode, type, range, pulses, fv_digits, filter_type, filter_constant, filter_power;
    std::array<OdRef, 4> filter_in;
    std::array<OdRef, 3> filter_out;
    OdRef scaling1_fv, scaling1_pv, scaling2_fv, scaling2_pv, span_start, span_end, error_enable, hysteresis,
        delay, polarity, pullup;
    // Outputs.
    OdRef field_value, process_value, di_state;
    blocks::AnalogInput ai;
    Pins pins;
    bool level_high_before = false;  // for the latched polarity's LOW->HIGH edge
    bool latched_state = false;
    bool on_off_state = false;  // mode 20 hysteresis
    std::optional<blocks::InputRange> input_class;
    std::int64_t sensor_type = -1;  // 6110h as last seen: a rewrite of the same type is no change
    std::unique_ptr<DeviceFault> high, low;
  };

  blocks::AnalogInputParams ParamsOf(const Channel& c) const;
  double Measured(const Channel& c) const;
  bool DigitalState(const Channel& c) const;

  canopen::ObjectDictionary& od_;
  const DataLoggerIo& io_;
  OdRef auto_updates_;
  std::array<Channel, kAnalogInputs> channels_;
};

}  // namespace canfleet::devices::datalogger
