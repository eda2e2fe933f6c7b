#pragma once
/// @file NMT states and commands with the values they carry on the bus (CiA 301 §7.2.8.3): the
/// vocabulary that the node's stack, the orchestrator's master, telemetry and the tools share.
/// Below all of them, so that none includes another's headers for it. Which services run in which
/// state is the stack's rule: node/canopen/common/nmt_state.hpp.

#include <cstdint>

namespace canfleet::canopen {

/// NMT states with the values they carry in heartbeat and guarding frames (CiA 301 §7.2.8.3.2).
enum class NmtState : std::uint8_t {
  kInitialising = 0x00,  ///< only ever seen as the boot-up message
  kStopped = 0x04,
  kOperational = 0x05,
  kPreOperational = 0x7F,
};

/// NMT command specifiers (CiA 301 §7.2.8.3.1).
enum class NmtCommand : std::uint8_t {
  kStart = 0x01,
  kStop = 0x02,
  kEnterPreOperational = 0x80,
  kResetNode = 0x81,
  kResetCommunication = 0x82,
};

/// "initialising", "stopped", "operational", "pre-operational"; "unknown" for other values.
const char* ToString(NmtState state);

}  // namespace canfleet::canopen
