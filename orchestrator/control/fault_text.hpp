#pragma once
/// @file Faults as people read and type them: the CLI's kind names ("heartbeat-loss", from the
/// table of fault kinds, fault_kinds.hpp) and a one-line summary of a FaultSpec, shared by the CLI,
/// the fleet manager (FaultInjected.summary, FaultStatus.summary) and the topology loader's messages.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "orchestrator/control/canfleet_control.pb.h"
#include "orchestrator/control/fault_kinds.hpp"

namespace canfleet::control {

/// The CLI name of `kind`: "bus-off", "heartbeat-loss", "rpdo-timeout", "drop", "delay",
/// "corrupt", "duplicate", "partition", "babbling-idiot", "error-passive", "kill", "restart",
/// "power-cycle"; "unspecified" for FAULT_KIND_UNSPECIFIED and unknown values.
std::string_view FaultKindName(FaultKind kind);

/// The kind named `name`: a CLI name, or the enum's own name ("HEARTBEAT_LOSS"); case and '-'/'_'
/// do not matter. nullopt for anything else, including "unspecified".
std::optional<FaultKind> ParseFaultKind(std::string_view name);

/// Every CLI name, in the enum's order (for CLI11's IsMember and help texts).
const std::vector<std::string>& FaultKindNames();

/// One line saying what the fault does, from the spec alone (the fleet manager fills in `bus`
/// before asking when the spec left it to the node's first bus):
///   "heartbeat-loss of quad-5 on can0 (to all receivers), until cleared"
///   "drop of frames 0x185 from quad-5 on can0 (to quad-6), probability 0.5 (seed 7), for 10s"
///   "delay of all frames from any node on can1 by 10ms + 0..5ms, for 100 frames"
///   "partition of can0 into [quad-5, quad-6] and [quad-7], until cleared"
///   "bus-off of quad-5 on can0, held for 2s (every recovery attempt fails until then)"
///   "restart of quad-5"
std::string SummarizeFault(const FaultSpec& spec);

/// A CAN identifier as the summaries write it: "0x185" (3 hex digits), "0x18FF0001" (extended).
std::string FormatCanId(std::uint32_t id, bool extended);

}  // namespace canfleet::control
