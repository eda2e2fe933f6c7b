#include "node/devices/datalogger_tc_analog/device_fault.hpp"

namespace canfleet::devices::datalogger {

DeviceFault::DeviceFault(Scheduler& scheduler, std::span<canopen::CanopenStack* const> stacks,
                         canopen::ErrorEntry entry, std::uint8_t behaviour_sub) {
  for (canopen::CanopenStack* stack : stacks)
    ports_.push_back(std::make_unique<DelayedFault>(scheduler, *stack, entry, behaviour_sub));
}

void DeviceFault::Set(bool present) {
  for (auto& port : ports_)
    port->Update(present, Duration::zero());
}

void DeviceFault::ResetPort(std::size_t port) {
  if (port < ports_.size()) ports_[port]->Reset();
}

}  // namespace canfleet::devices::datalogger
