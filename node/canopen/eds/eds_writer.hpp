#pragma once
/// @file Writing an EdsFile as a CiA 306 v1.3 EDS or DCF.

#include <chrono>
#include <ostream>
#include <string>

#include "node/canopen/eds/eds_error.hpp"
#include "node/canopen/eds/eds_file.hpp"

namespace canfleet::canopen {

/// Writes `file` as CiA 306 text: [FileInfo], [DeviceInfo], [DummyUsage], [Comments] (if any),
/// for a DCF [DeviceComissioning], then each object list followed by its object and sub-object
/// sections. Sub-objects are always written expanded (CompactSubObj is not reproduced).
/// Node-relative defaults and limits are written as "$NODEID+x". A DCF adds ParameterValue with
/// the current value of every sub-object. Reading the output gives the same dictionary.
/// @throws EdsError if the dictionary has no CiA 306 spelling: text with line breaks or leading/
///         trailing blanks, a value whose size does not match its type, an unknown data type, a
///         VAR without sub-index 0 or with more sub-objects.
void WriteEds(const EdsFile& file, std::ostream& out, EdsFormat format);

/// WriteEds into a string.
std::string WriteEdsString(const EdsFile& file, EdsFormat format);

/// Sets ModificationDate/ModificationTime (and CreationDate/CreationTime when empty) to `when`
/// (UTC) in CiA 306 spelling, mm-dd-yyyy and hh:mm(AM|PM). The caller passes the time so the
/// writer itself never reads a clock.
void StampFileInfo(FileInfo& info, std::chrono::system_clock::time_point when);

/// Which CiA 306 object list an index belongs to when writing: MandatoryObjects for 1000h, 1001h
/// and 1018h, ManufacturerObjects for 2000h..5FFFh, OptionalObjects for the rest.
enum class EdsObjectList : std::uint8_t { kMandatory, kOptional, kManufacturer };
EdsObjectList ObjectListFor(std::uint16_t index);

}  // namespace canfleet::canopen
