#include "bus/bus_port.hpp"

namespace canfleet {

const char* ToString(ControllerState state) {
  switch (state) {
    case ControllerState::kErrorActive:
      return "error-active";
    case ControllerState::kErrorPassive:
      return "error-passive";
    case ControllerState::kBusOff:
      return "bus-off";
  }
  return "unknown";
}

}  // namespace canfleet
