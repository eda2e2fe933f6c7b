#include "node/devices/wake_on_change.hpp"

namespace canfleet::devices {

void WakeOnChanges(canopen::CanopenStack& stack, SimulatedIo& io, std::function<void()> wake) {
  for (auto& [index, object] : stack.od().objects()) {
    for (auto& [sub_index, sub] : object.subs)
      sub.listeners.push_back([wake](canopen::SubObject&, canopen::Origin) { wake(); });
  }
  stack.emcy().AddActiveListener(wake);
  io.Subscribe([wake](const IoSignal& signal) {
    if (signal.direction() == IoDirection::kInput) wake();
  });
}

}  // namespace canfleet::devices
