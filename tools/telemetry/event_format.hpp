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

/// "12:00:01.234" (UTC): the time of day, for `canfleet top`'s narrow event lines.
std::string FormatTimeOfDay(WallTime time);

/// "2024-05-01T12:00:01.234Z can0 #5 quad-5 EMCY 8130h reg=11h mfr=00 00 00 00 00 (life guard or
/// heartbeat error)" (the node's name when known). A verdict: "2024-05-01T12:00:01.234Z demo
/// VERDICT cycle 2: pass  topologies/demo.textproto:284  quad-6-emcy: ..." (the whole result line,
/// as `canfleet test` prints it). Nothing is cut: a value the publisher had to cut ends in "...".
/// `compact` (for `canfleet top`): the time of day only, and a verdict as "FAIL quad-6-emcy
/// (cycle 2): <what was expected and seen>".
std::string FormatEventText(const FleetEvent& event, bool compact = false);
/// One JSON object, no newline. Keys: time, type, bus, node, replay, and per type:
/// seen/gone/nmt/controller/error-register: from, to; hb-consumer: peer, from, to;
/// emcy: code, error_register, manufacturer (array), bus_time_ns, text;
/// fault: fault_id, action, kind, target_node, parameters (object), bus_time_ns;
/// verdict: source, index, scenario, cycle, result, name, line, text, text_cut, scenario_time_s.
/// A node event of a node whose name is known has "name" too.
std::string FormatEventJson(const FleetEvent& event);

/// JSON string literal with escapes (RFC 8259 §7).
std::string JsonString(std::string_view text);

}  // namespace canfleet::tools
