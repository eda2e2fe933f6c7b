#include "node/devices/quad_controller/load_faults.hpp"

#include "node/devices/quad_controller/quad_io.hpp"
#include "node/devices/quad_controller/quad_objects.hpp"

namespace canfleet::devices::quad {

LoadFaults::LoadFaults(Scheduler& scheduler, canopen::CanopenStack& stack, std::uint8_t description,
                       std::uint8_t channel, std::uint8_t behaviour_sub)
    : short_(scheduler, stack, MakeErrorEntry(kEmcyShortCircuit, description, channel), behaviour_sub),
      open_(scheduler, stack, MakeErrorEntry(kEmcyOpenCircuit, description, channel), behaviour_sub) {}

bool LoadFaults::Update(bool monitored, const IoSignal& load, Duration delay) {
  const bool short_changed = short_.Update(monitored && load.Is(kLoadShort), delay);
  const bool open_changed = open_.Update(monitored && load.Is(kLoadOpen), delay);
  return short_changed || open_changed;
}

void LoadFaults::Reset() {
  short_.Reset();
  open_.Reset();
}

}  // namespace canfleet::devices::quad
