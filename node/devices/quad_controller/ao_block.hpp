#pragma once
/// @file The Quad's analog (proportional current) output block (DS-404 AO; AX020506 §2.6, §3.5):
/// POUT1-4 while 6310h says current (20). Runs every millisecond.
///
/// Per output n:
/// - Received PV path (§3.5.23-24): when 6F52h.n = 1 the block copies 7F50h.n to 7300h.n, sets
///   6F52h.n back to 0 (each PV must be validated again), and 7330h.n follows from 7300h.n by the
///   line (7320h PV1 → 7321h FV1), (7322h PV2 → 7323h FV2) (§3.5.20). Equal PVs (the default)
///   make the line degenerate and 7330h = 7300h.
/// - Target current (mA, 0-2000): control 3010h = 0 → 7330h; 1-6 → the profile 3020h
///   (ao_profile.hpp) of that input's field value, if the input is in normal mode (6112h = 1,
///   §3.5.1 note 1), else 0.
/// - Ramps (§3.5.8-10): 3080h/3090h ms for 0 ↔ the highest current of the profile (max of
///   3030h-3050h), or 2000 mA under CAN control; 30A0h 0 = none, 1 = always, 2 = unless CAN.
/// - Then, in this order (§4.2): stopped → 0 mA; controller fault state with 6340h = 1 → 7341h
///   (written into 7330h when the fault state begins); CAN control outside operational → 0 mA.
///   These changes are immediate: "in emergency shutoffs ramps are never used" (§3.5.10).
/// - Dither 3060h/3070h rides on the current whatever the control (§2.6); the simulated output
///   reports its amplitude and frequency, and 30C0h the mean current.
/// - Load faults: short 2320h / open 3300h with description 04h, delay 30B0h, reaction 1029h
///   sub 5.

#include <array>
#include <memory>

#include "clock/scheduler.hpp"
#include "node/canopen/stack/canopen_stack.hpp"
#include "node/devices/od_ref.hpp"
#include "node/devices/quad_controller/ai_block.hpp"
#include "node/devices/quad_controller/load_faults.hpp"
#include "node/devices/quad_controller/output_conditions.hpp"
#include "node/devices/quad_controller/quad_io.hpp"

namespace canfleet::devices::quad {

class AoBlock {
 public:
  AoBlock(canopen::CanopenStack& stack, Scheduler& scheduler, QuadIo& io);
  AoBlock(const AoBlock&) = delete;
  AoBlock& operator=(const AoBlock&) = delete;

  /// One millisecond of the output stage. Returns true if the block's state changed (a ramp
  /// moving, a load fault); outputs and objects it moves wake the ticks through their listeners.
  bool Update(const OutputConditions& conditions, const AiBlock& ai);
  void Reset();

 private:
  struct Refs {
    OdRef output_type, control, response, min_current, breakpoint_current, max_current;
    OdRef dither_frequency, dither_amplitude, ramp_up, ramp_down, ramp_control, error_delay, measured;
    OdRef process_value, scaling1_pv, scaling1_fv, scaling2_pv, scaling2_fv, field_value;
    OdRef fault_mode, fault_fv, received_pv, pv_status;
  };
  struct Output {
    double present = 0;  ///< mA, after ramps and overrides
    std::unique_ptr<LoadFaults> faults;
  };

  void ApplyReceivedPv(int n);
  double Target(int n, const AiBlock& ai) const;
  double Highest(int n) const;
  void Ramp(int n, double target);
  void Publish(int n);

  QuadIo& io_;
  std::array<Refs, kPouts> refs_;
  std::array<std::array<OdRef, 6>, kInputs> input_points_;  ///< 2020h..2070h per input
  std::array<Output, kPouts> outputs_;
};

}  // namespace canfleet::devices::quad
