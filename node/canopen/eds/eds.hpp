#pragma once
/// @file The EDS module in one include: CiA 306 v1.3 EDS/DCF reading (ReadEds, ParseEds),
/// writing (WriteEds) and comparison (DiffEdsFiles), with EdsError for every failure.

#include "node/canopen/eds/eds_compare.hpp"  // IWYU pragma: export
#include "node/canopen/eds/eds_error.hpp"    // IWYU pragma: export
#include "node/canopen/eds/eds_file.hpp"     // IWYU pragma: export
#include "node/canopen/eds/eds_reader.hpp"   // IWYU pragma: export
#include "node/canopen/eds/eds_writer.hpp"   // IWYU pragma: export
