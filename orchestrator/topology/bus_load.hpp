#pragma once
/// @file The periodic load a bus is offered (periodic_traffic.hpp): every periodic TPDO, heartbeat
/// and SYNC frame at its rate, each as long as the physics model's worst case for its identifier
/// format and data length (bus/physics/frame_timing.hpp MaxFrameBits: every possible stuff bit,
/// as CAN schedulability analysis counts frames), against the bus's bit rate. Frames sent only on
/// a change, on request or acyclically do not count. Internal to the loader.

#include <string>

#include "orchestrator/topology/canfleet_topology.pb.h"
#include "orchestrator/topology/periodic_traffic.hpp"
#include "orchestrator/topology/topology_warning.hpp"

namespace canfleet::topology::detail {

/// `bus` (its bit rate already defaulted) offered `traffic`.
BusLoad OfferedLoad(const Bus& bus, const BusTraffic& traffic);

/// Why a bus's load cannot work ("bus can0: periodic traffic offers ..."), or "" when it can: a
/// paced bus offered more than 100 % of its bit rate.
std::string OverloadReason(const BusLoad& load);

}  // namespace canfleet::topology::detail
