#include "node/devices/quad_controller/di_block.hpp"

namespace canfleet::devices::quad {

DiBlock::DiBlock(canopen::CanopenStack& stack, const QuadIo& io)
    : stack_(stack),
      io_(io),
      level_(stack.od(), kDiLevel, 1),
      polarity_(stack.od(), kDiPolarity, 1),
      read_state_(stack.od(), kDiReadState, 1) {}

bool DiBlock::Sample(const AiBlock& ai) {
  std::uint8_t bits = 0;
  for (int ch = 0; ch < kInputs; ++ch) {
    bool on = false;
    switch (ai.Mode(ch)) {
      case OperatingMode::kDigital: {
        const bool active_high = level_.Bit(static_cast<unsigned>(ch));
        const IoSignal& pin = *io_.din_level[ch];
        // A floating pin reads what the 2000h resistor pulls it to: low (pull-down) when active
        // high, high (pull-up) when active low; either way "not active".
        const bool high = pin.Is(kLevelHigh) || (pin.Is(kLevelOpen) && !active_high);
        on = (active_high ? high : !high) != polarity_.Bit(static_cast<unsigned>(ch));
        break;
      }
      case OperatingMode::kOnOff:
        on = ai.OnOff(ch);
        break;
      default:
        break;
    }
    if (on) bits = static_cast<std::uint8_t>(bits | (1u << ch));
  }
  const bool changed = bits != state_;
  state_ = bits;
  if (read_state_.Set(bits)) stack_.pdo().NotifyChanged(read_state_.sub());
  return changed;
}

}  // namespace canfleet::devices::quad
