#pragma once
/// @file What `canfleet top` and `canfleet watch` say when they see no fleet at all.

#include <string>

#include "telemetry/dds.hpp"

namespace canfleet::tools {

/// Where `tool` looked (DDS domain, configuration) and why a fleet may be elsewhere. Seeing nothing
/// at all is a configuration mismatch far more often than a quiet fleet (issue 29: a second terminal
/// saw nothing of the demo), so the tools say so instead of showing an empty table.
std::string NothingSeenHint(const char* tool, const telemetry::DdsOptions& dds);

}  // namespace canfleet::tools
