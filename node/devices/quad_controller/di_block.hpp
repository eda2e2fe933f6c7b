#pragma once
/// @file The Quad's digital input block (DS-404 DI; AX020506 §2.2, §3.2). Sampled with the
/// analog inputs (every 10 ms), it writes 6000h bit n for input n (bit 0-3 DIN1-4 = AIN1-4,
/// bit 4-5 DIN5-6 = FIN1-2):
/// - 6112h = 10 (digital): the pin through 2000h (1 = active high: pull-down, the input is on when
///   driven high; 0 = active low: pull-up, on when pulled to ground), then 6002h polarity
///   (1 = inverted).
/// - 6112h = 20 (ON/OFF with thresholds): the AI block's 2001h/2002h state; 6002h is ignored.
/// - Other modes: 0 (§3.2.4).
/// A change of 6000h is an event for the TPDOs mapping it (TPDO3 by default).

#include <cstdint>

#include "node/canopen/stack/canopen_stack.hpp"
#include "node/devices/od_ref.hpp"
#include "node/devices/quad_controller/ai_block.hpp"
#include "node/devices/quad_controller/quad_io.hpp"

namespace canfleet::devices::quad {

class DiBlock {
 public:
  DiBlock(canopen::CanopenStack& stack, const QuadIo& io);

  /// Returns true if 6000h changed.
  bool Sample(const AiBlock& ai);
  /// Bit `ch` of 6000h.
  bool State(int ch) const { return ((state_ >> ch) & 1) != 0; }

 private:
  canopen::CanopenStack& stack_;
  const QuadIo& io_;
  OdRef level_, polarity_, read_state_;
  std::uint8_t state_ = 0;
};

}  // namespace canfleet::devices::quad
