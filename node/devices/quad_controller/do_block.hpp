#pragma once
/// @file The Quad's digital output block (DS-404 DO; AX020506 §2.5, §3.4): DOUT, and POUT1-4 while
/// 6310h says digital (1000). Runs every millisecond.
///
/// Per output (bit n of the 8-line objects; sub-index n+1 of 3001h/300Bh):
/// - Control (3001h): 0 = 6200h bit; 1-6 = AIN1-4/FIN1-2 as ON/OFF inputs with 2001h/2002h
///   whatever their 6112h mode (§3.4.1 note 1); 11-16 = DIN1-6, which read OFF unless that input
///   is in digital mode 10 (note 2).
/// - Response (3002h bit): normal = control XOR polarity 6202h; latched = every OFF→ON edge of the
///   control toggles the output, 6202h ignored (§3.4.2).
/// - Then, in this order (§4.2): stopped → off (fault settings ignored); controller fault state
///   with 6206h bit set → 6207h bit; CAN control outside operational → off.
/// - 300Ch = the resulting states (POUTs not digital read 0), an event for its TPDO (TPDO3).
/// - Load faults: POUT1-4 short 2320h / open 3300h with description 02h; DOUT any load fault
///   FF02h (§4.1 "Error at Digital Output (DOUT only)"); delay 300Bh; reaction 1029h sub 4.

#include <array>
#include <memory>

#include "clock/scheduler.hpp"
#include "node/canopen/stack/canopen_stack.hpp"
#include "node/devices/delayed_fault.hpp"
#include "node/devices/od_ref.hpp"
#include "node/devices/quad_controller/ai_block.hpp"
#include "node/devices/quad_controller/di_block.hpp"
#include "node/devices/quad_controller/load_faults.hpp"
#include "node/devices/quad_controller/output_conditions.hpp"
#include "node/devices/quad_controller/quad_io.hpp"

namespace canfleet::devices::quad {

class DoBlock {
 public:
  DoBlock(canopen::CanopenStack& stack, Scheduler& scheduler, QuadIo& io);
  DoBlock(const DoBlock&) = delete;
  DoBlock& operator=(const DoBlock&) = delete;

  /// One millisecond of the output stage. Returns true if the block's state changed (edges,
  /// latches, load faults); outputs and objects it moves wake the ticks through their listeners.
  bool Update(const OutputConditions& conditions, const AiBlock& ai, const DiBlock& di);
  void Reset();

  /// POUT `n` (0-3) is in digital mode (6310h = 1000).
  bool Owns(int pout) const;

 private:
  bool Control(int output, const AiBlock& ai, const DiBlock& di) const;
  void Drive(int output, bool on);

  canopen::CanopenStack& stack_;
  QuadIo& io_;
  OdRef write_state_, polarity_, response_, fault_mode_, fault_state_, read_state_;
  std::array<OdRef, kDigitalOutputs> control_, error_delay_;
  std::array<OdRef, kPouts> output_type_, measured_current_;
  std::array<bool, kDigitalOutputs> previous_control_{};
  std::array<bool, kDigitalOutputs> latch_{};
  std::array<std::unique_ptr<LoadFaults>, kPouts> pout_faults_;
  std::unique_ptr<DelayedFault> dout_fault_;
};

}  // namespace canfleet::devices::quad
