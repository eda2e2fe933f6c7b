#pragma once
/// @file The Quad's analog/pulse input block (DS-404 AI; AX020506 §2.3, §2.4, §3.3).
///
/// Per input, every 10 ms (§2.3 "sampled every 10ms"):
///   pin --6110h/6112h--> field value 7100h --filter 61A0h/61A1h--> scaling 7120h-7123h + 7124h
///       --> process value 7130h
/// - Field value units: mV (sensor types 40, 42), µA (51, 52), 0.01 % duty (10000), Hz (60). A
///   reading is clamped to its type's full scale. Disabled (6112h = 0) and digital (10) inputs read
///   0 in 7100h/7130h.
/// - Frequency inputs count pulses over the 2090h window and hold the result until the next
///   window ends (§3.3.9); they are never filtered (§3.3.23).
/// - The filter acts on the process value path only: 7100h stays the measurement, which error
///   checking, ON/OFF thresholds and output control use (§2.3 "uses the input field value").
/// - Scaling through (7120h, 7121h) and (7122h, 7123h); equal field values (the default: all 0)
///   make the line degenerate, and the process value then equals the filtered field value.
///   6132h only says how many decimals the PV carries: the calibration PVs are in the same units.
/// - 6125h autozero "zero" (0x6F72657A) sets 7124h so that 7130h reads 0 (§3.3.20).
/// - ON/OFF state with thresholds 2001h/2002h is kept for every input whatever its mode: DO
///   control inputs 1-6 use it (§3.4.1 note 1), and mode 20 reports it through the DI block.
/// - Error checking (20A0h bit, modes 1 and 20 only, §3.3.10): 7100h < 2010h → FF00h "out of range
///   low", > 2080h → FF01h "out of range high", after 20B0h ms (§4.2), reaction 1029h sub 3.

#include <array>
#include <cstdint>
#include <memory>
#include <tuple>

#include "clock/scheduler.hpp"
#include "node/canopen/stack/canopen_stack.hpp"
#include "node/devices/delayed_fault.hpp"
#include "node/devices/od_ref.hpp"
#include "node/devices/quad_controller/quad_io.hpp"
#include "node/devices/quad_controller/quad_objects.hpp"

namespace canfleet::devices::quad {

class AiBlock {
 public:
  AiBlock(canopen::CanopenStack& stack, Scheduler& scheduler, const QuadIo& io);
  AiBlock(const AiBlock&) = delete;
  AiBlock& operator=(const AiBlock&) = delete;

  /// Counts pulses of frequency inputs; call every millisecond. Returns true if anything changed
  /// (always, while a measuring window runs).
  bool CountPulses();
  /// Samples every input; call every 10 ms. Returns true if anything changed (a filter still
  /// settling or a repeating average counting changes something at every sample).
  bool Sample();
  /// A frequency input is measuring: its window runs every millisecond, whatever the inputs.
  bool Counting() const;
  /// Reset application: filters, windows, thresholds and faults start over.
  void Reset();

  /// 7100h of input `ch` as of the last sample.
  int FieldValue(int ch) const { return channels_[ch].fv; }
  /// ON/OFF state from the 2001h/2002h thresholds.
  bool OnOff(int ch) const { return channels_[ch].on; }
  OperatingMode Mode(int ch) const { return static_cast<OperatingMode>(refs_[ch].mode.Get()); }
  SensorType Type(int ch) const { return static_cast<SensorType>(refs_[ch].type.Get()); }

 private:
  struct Refs {
    OdRef type, mode, fv, pv, low_threshold, high_threshold, error_min, error_max, error_delay;
    OdRef filter_type, filter_constant, fv1, pv1, fv2, pv2, offset, window;
  };
  struct Channel {
    int fv = 0;
    bool on = false;
    double filtered = 0;  ///< last filter output (field value units)
    bool filter_started = false;
    double sum = 0;  ///< repeating average
    int count = 0;
    std::uint16_t last_type = 0;
    std::uint8_t last_mode = 0xFF;
    // Frequency counting: micro-pulses so that whole hertz add up exactly.
    std::uint64_t phase_upulses = 0;
    std::uint64_t window_start_upulses = 0;
    int window_elapsed_ms = 0;
    int frequency_fv = 0;
    std::unique_ptr<DelayedFault> low, high;

    /// Everything a tick may change (on-demand ticks compare it before and after a tick).
    auto State() const {
      return std::tuple(fv, on, filtered, filter_started, sum, count, last_type, last_mode, phase_upulses,
                        window_start_upulses, window_elapsed_ms, frequency_fv, low->state(), high->state());
    }
  };

  int Measure(int ch) const;
  /// The filtered field value, or false when a repeating average has not completed a block.
  bool Filter(int ch, int fv, double& out);
  double Scale(int ch, double fv) const;
  void WriteProcessValue(int ch, double pv);
  void Autozero(int ch);
  void ResetChannel(Channel& c);

  const QuadIo& io_;
  OdRef error_check_enable_;
  std::array<Refs, kInputs> refs_;
  std::array<Channel, kInputs> channels_;
};

}  // namespace canfleet::devices::quad
