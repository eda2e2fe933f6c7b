#pragma once
/// @file What wakes a device's on-demand ticks (periodic_tick.hpp; design decision 10): every
/// event through which something a function block reads may change between two ticks.
///
/// WakeOnChanges installs `wake` as
///  - a listener on every sub-object of the stack's dictionary: SDO and RPDO writes, stored
///    parameters and restored defaults, the services' own objects (1001h/1003h...), and the
///    device's own writes (a block's output object is another block's input);
///  - a listener of the set of active errors (Emcy::AddActiveListener): the fault state;
///  - a listener of the simulated I/O that reacts to inputs (outputs are what the blocks compute).
/// NMT state changes come through StackHooks::on_state_changed, which the device sets in
/// ConfigureStack (the stack's hooks are fixed when it is built), and a reset application through
/// on_reset_application.

#include <functional>

#include "node/canopen/stack/canopen_stack.hpp"
#include "node/devices/simulated_io.hpp"

namespace canfleet::devices {

/// `wake` must stay valid as long as the dictionary, the stack and `io` (it may capture the device).
void WakeOnChanges(canopen::CanopenStack& stack, SimulatedIo& io, std::function<void()> wake);

}  // namespace canfleet::devices
