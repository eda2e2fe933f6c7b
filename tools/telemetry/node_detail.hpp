#pragma once
/// @file The `canfleet top` node detail screen (select a node, Enter): what the table has no room
/// for. A pure function of a FleetView, like the table, so tests check it without DDS or a terminal.

#include <string>

#include "tools/telemetry/top_format.hpp"

namespace canfleet::tools {

/// One node's screen: its status, heartbeat and PDO counters (NodeStatus), its simulated I/O with
/// units (IoSnapshot) and the EMCYs it sent as the monitor saw them on the Emcy topic (newest
/// first), fitted to the settings' width and height. A node no longer known says so.
std::string RenderNodeDetail(const FleetView& view, const NodeKey& key, const RenderSettings& settings);

/// A simulated value as text: integers without decimals, others with up to 3 ("1200", "23.5").
std::string FormatIoValue(double value);

}  // namespace canfleet::tools
