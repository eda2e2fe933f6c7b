#pragma once
/// @file The `@key value` lines of a dictionary table: the EDS's [FileInfo], [DeviceInfo],
/// [DummyUsage] and [Comments] (FORMAT.md, "File-level facts").

#include <cstddef>
#include <string_view>

#include "node/canopen/eds/eds_file.hpp"

namespace canfleet::devices::od_table {

/// Which facts a table set; the PDO counts default to the number of PDO objects when not set.
struct FactsSeen {
  bool nr_of_rx_pdo = false;
  bool nr_of_tx_pdo = false;
};

/// Applies one `@key value` line (`line` is the text after '@').
/// @throws OdTableError for an unknown key or a malformed value
void ApplyFact(std::string_view line, std::string_view file_name, std::size_t line_number,
               canopen::EdsFile& out, FactsSeen& seen);

}  // namespace canfleet::devices::od_table
