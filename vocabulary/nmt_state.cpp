#include "vocabulary/nmt_state.hpp"

namespace canfleet::canopen {

const char* ToString(NmtState state) {
  switch (state) {
    case NmtState::kInitialising:
      return "initialising";
    case NmtState::kStopped:
      return "stopped";
    case NmtState::kOperational:
      return "operational";
    case NmtState::kPreOperational:
      return "pre-operational";
  }
  return "unknown";
}

}  // namespace canfleet::canopen
