#include "node/devices/wake_on_change.hpp"

namespace canfleet::devices {

void WakeOnChanges(canopen::CanopenStack& stack, SimulatedIo& io, std::function<void()> wake) {
  // One listener for the whole dictionary: one per sub-object cost ~130 bytes each (idle RSS).
  stack.od().AddWriteListener([wake](canopen::SubObject&, canopen::Origin) { wake(); });
  stack.emcy().AddActiveListener(wake);
  io.Subscribe([wake](const IoSignal& signal) {
    if (signal.direction() == IoDirection::kInput) wake();
  });
}

}  // namespace canfleet::devices
