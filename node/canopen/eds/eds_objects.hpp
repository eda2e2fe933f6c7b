#pragma once
/// @file Reads the object dictionary of an EDS/DCF (internal to the reader): object and
/// sub-object sections, CompactSubObj expansion with its [xxxxName]/[xxxxValue] sections, and
/// the object lists.

#include <string_view>

#include "node/canopen/eds/eds_file.hpp"
#include "node/canopen/eds/eds_reader.hpp"
#include "node/canopen/eds/eds_sections.hpp"

namespace canfleet::canopen {

/// Fills `out.od` and `out.node_id_limits`. Needs `out.dcf_node_id` already read (ParameterValue
/// may be "$NODEID+x"). Throws EdsError.
void ReadObjects(const EdsSections& sections, std::string_view file_name, EdsFile& out);

}  // namespace canfleet::canopen
