#pragma once
/// @file How `canfleet watch` prints events: one per line, as text for people or JSON for scripts.

#include <cstdint>
#include <string>

#include "tools/telemetry/fleet_view.hpp"

namespace canfleet::tools {

/// CiA 301 §7.2.7.3.1 table 21 text for an emergency error code (most specific class known).
const char* DescribeEmcyCode(std::uint16_t code);

/// ISO 8601 UTC with milliseconds: "2024-05-01T12:00:01.234Z".
std::string FormatTime(WallTime time);

/// "2024-05-01T12:00:01.234Z can0 #5 EMCY 8130h reg=11h mfr=00 00 00 00 00 (life guard or heartbeat error)"
std::string FormatEventText(const FleetEvent& event);
/// One JSON object, no newline. Keys: time, type, bus, node, replay, and per type:
/// seen/gone/nmt/controller/error-register: from, to; hb-consumer: peer, from, to;
/// emcy: code, error_register, manufacturer (array), bus_time_ns, text;
/// fault: fault_id, action, kind, target_node, parameters (object), bus_time_ns.
std::string FormatEventJson(const FleetEvent& event);

/// JSON string literal with escapes (RFC 8259 §7).
std::string JsonString(std::string_view text);

}  // namespace canfleet::tools
