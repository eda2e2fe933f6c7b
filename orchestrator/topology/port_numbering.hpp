#pragma once
/// @file CAN ports in topology files as the manuals print them. A message that names a port of a
/// multi-port node (an SDO write, an expectation) says `can: 2` for the manual's CAN2; the loader
/// turns that into the 0-based `port` the orchestrator and its wire protocol use. `port: 1` (the
/// old, 0-based spelling) still loads, with a deprecation note (issue 29: one port numbering).

#include <google/protobuf/message.h>

#include "orchestrator/topology/located_error.hpp"

namespace canfleet::topology::detail {

/// Walks `message` and every message nested in it. Where one has both a `can` and a `port` field:
/// `can: N` sets port = N - 1 (`can` stays as written, `port` being what the rest reads); a
/// non-zero `port` alone is noted as deprecated; both at once, or `can` out of 1..2, are refused.
/// `scope` locates `message`'s fields in the file.
void NumberPortsAsManuals(const Scope& scope, google::protobuf::Message& message);

/// The field a check of a port should point at: "can" when the file wrote it, else "port".
const char* PortFieldName(const google::protobuf::Message& message);

/// "CAN2": the manual's name of the 0-based port.
std::string CanName(std::uint32_t port);

}  // namespace canfleet::topology::detail
