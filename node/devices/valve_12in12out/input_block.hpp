#pragma once
/// @file The valve's twelve inputs (UMAX020411A §1.2 digital input block, §1.3 analog input block,
/// §3.3.2-3.3.15, §3.4.1-3.4.18): UI1-UI7 and DI1-DI5.
///
/// Per input and run, by 6112h (Table 4):
/// - 0 off: 7100h = 7130h = 6020h = 0; not available as a control source.
/// - 10 digital (§1.2): the pin level (open = the 2020h pull: pull-up reads high, none or pull-down
///   low) through 2010h polarity (Table 3: normal, inverse, latched = every LOW->HIGH edge toggles)
///   gives 6020h; 7100h and 7130h carry the same 0/1 (Table 10's digital row is OFF/ON). 2030h
///   debounces in nanoseconds to microseconds, below the emulation's millisecond: no effect.
/// - 1 normal, 20 analog and on/off (§1.3 Figure 6): the pin in its 6110h base unit (V, mA, kOhm,
///   Hz, RPM when 2101h != 0, %) through blocks::AnalogInput (x 10^2102h, 61A0h/61A1h filter once
///   per ms, 7100h FV, span check 2110h-2112h with 7148h/7149h, 7120h-7123h line to 7130h PV). Mode 20
///   also drives 6020h from the FV (Figure 5 is lost; choice: ON at FV >= 7122h, OFF at FV <= 7120h,
///   held between). Mode 1 leaves 6020h at 0 ("for all other operating modes, 6020h will always be
///   zero").
/// - A span flag held for 2112h on UI1-UI7 raises 40nnF001h (low) / 20nnF001h (high) with EMCY
///   F001h and the 1029h sub 3 reaction (Table 33); it clears with the flag (hysteresis 2111h).
///   DI1-DI5 have no EMCY (§1.3 "it only applies to the 7 Analog Inputs"), but a faulted span still
///   marks them in error as a control source.
/// A change of 6110h, 2100h, 6112h or of 2101h between zero and non-zero starts the channel over
/// (filter from zero, flags cleared, latch OFF).
///
/// Time: Run(elapsed) first carries the time before this run with the previous run's pin value
/// and parameters (the node may have slept through it: nothing changed then), then one
/// millisecond with the new ones, so an idle stretch never runs a filter or a fault delay with a
/// value that arrived afterwards. NextWake() says when the inputs need the next run.

#include <array>
#include <chrono>
#include <memory>
#include <optional>

#include "clock/scheduler.hpp"
#include "node/canopen/stack/canopen_stack.hpp"
#include "node/devices/blocks/analog_input.hpp"
#include "node/devices/blocks/signal.hpp"
#include "node/devices/delayed_fault.hpp"
#include "node/devices/od_ref.hpp"
#include "node/devices/valve_12in12out/valve_io.hpp"

namespace canfleet::devices::valve {

class InputBlock {
 public:
  InputBlock(canopen::CanopenStack& stack, Scheduler& scheduler, const ValveIo& io);
  InputBlock(const InputBlock&) = delete;
  InputBlock& operator=(const InputBlock&) = delete;

  /// Advances every input by `elapsed` (> 0) and writes 7100h, 7130h, 6020h.
  void Run(std::chrono::milliseconds elapsed);
  /// Time until an input needs the next run (a filter settling, a span delay counting).
  std::optional<std::chrono::milliseconds> NextWake() const;
  /// Reset application: every channel starts over; faults forgotten (the stack cleared them).
  void Reset();

  /// Input `ch` as a control source (Table 16 "Analog Input Function Block": 7100h or 6020h by
  /// 6112h; Table 17 limits 7120h/7122h; 2102h digits; error = span fault).
  blocks::Signal AsSource(int ch) const;
  /// 6020h of input `ch`.
  bool State(int ch) const { return channels_[ch].state; }

 private:
  struct Refs {
    OdRef type, mode, range, ppr, digits, pull, polarity, error_enable, hysteresis, delay, filter_type,
        filter_constant, scaling1_fv, scaling1_pv, scaling2_fv, scaling2_pv, span_start, span_end, fv, pv,
        state;
    std::array<OdRef, 4> filter_in;
    std::array<OdRef, 3> filter_out;
    OdRef filter_power;
  };
  struct Key {
    std::int64_t type = -1, range = -1, mode = -1;
    bool rpm = false;
    friend bool operator==(const Key&, const Key&) = default;
  };
  struct Channel {
    blocks::AnalogInput analog;
    blocks::AnalogInputParams params;  ///< as of the last run
    double measured = 0;               ///< as of the last run
    bool has_last = false;
    Key key;
    bool state = false;  ///< 6020h
    bool latch_raw = false;
    bool latch_seen = false;
    InputMode mode = InputMode::kOff;
    std::unique_ptr<DelayedFault> low, high;
  };

  blocks::AnalogInputParams ReadParams(int ch) const;
  double Measure(int ch, const Key& key) const;
  bool PinHigh(int ch) const;
  void RunDigital(int ch);
  void RunAnalog(int ch, std::chrono::milliseconds elapsed);
  void StartOver(Channel& c);

  const ValveIo& io_;
  std::array<Refs, kInputs> refs_;
  std::array<Channel, kInputs> channels_;
};

}  // namespace canfleet::devices::valve
