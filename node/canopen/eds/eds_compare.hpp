#pragma once
/// @file Comparing dictionaries and whole EDS files, for round-trip tests and the fuzz target.

#include <string>
#include <vector>

#include "node/canopen/eds/eds_file.hpp"

namespace canfleet::canopen {

/// The differences between two dictionaries, one readable line each
/// ("2000sub1 DataType: UNSIGNED8 != UNSIGNED16"); empty when they are equal. Compares indexes,
/// sub-indexes, names, object codes, ObjFlags, data types, access, PDO mapping, limits, defaults,
/// node-ID flags and, if `compare_values`, current values. CompactSubObj is not compared: the
/// writer expands it.
std::vector<std::string> DiffObjectDictionaries(const ObjectDictionary& a, const ObjectDictionary& b,
                                                bool compare_values);

/// Everything WriteEds(`format`) must keep through a write and a read: the dictionary (values
/// only for a DCF), node-relative limits, FileInfo, DeviceInfo, DummyUsage, Comments, and for a
/// DCF the [DeviceComissioning] contents.
std::vector<std::string> DiffEdsFiles(const EdsFile& a, const EdsFile& b, EdsFormat format);

}  // namespace canfleet::canopen
