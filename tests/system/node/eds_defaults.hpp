#pragma once
/// @file The sub-objects of an EDS with their default values, read the way a third-party master
/// tool reads them (CiA 306 v1.3 §4: [xxxx] and [xxxxsubN] sections, DataType, AccessType,
/// DefaultValue with $NODEID). Deliberately independent of node/canopen/eds/, so the system tests
/// compare a running node with the file itself rather than with the node's own reading of it.
/// Scope: what expanded EDS files use (no CompactSubObj, no DOMAIN defaults).

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "node/canopen/od/value.hpp"

namespace canfleet::system_test {

struct EdsDefault {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::string name;
  std::uint16_t data_type = 0;  ///< CiA 301 table 44 index (0x0007 = UNSIGNED32)
  std::string access;           ///< lower case: ro, wo, rw, rwr, rww, const
  std::string default_text;     ///< as written
  canopen::Bytes value;         ///< the default as the node must encode it, $NODEID applied

  bool readable() const { return access != "wo"; }
  bool writable() const { return access == "rw" || access == "wo" || access == "rwr" || access == "rww"; }
  /// "1800h.1 COB-ID used by TPDO".
  std::string Label() const;
};

struct EdsContents {
  std::vector<EdsDefault> entries;  ///< in (index, sub-index) order
  /// Problems with the file itself (an object listed but without a section, a missing key, an
  /// unparsable default ...), one line each.
  std::vector<std::string> problems;
};

/// Reads `path`; the $NODEID defaults get `node_id`.
EdsContents ReadEdsDefaults(const std::filesystem::path& path, std::uint8_t node_id);

class BusMaster;

/// Reads every entry of `eds` from node `node_id` by SDO and compares it with its default: same
/// size, same bytes. The answers that are not a value are the ones CiA 301 prescribes: a
/// write-only entry aborts with 06010001h (§7.2.4.3.17), and 1003h entries beyond the number of
/// errors with 08000024h (no data, §7.5.2.4). Every difference is one line of `mismatches`.
struct EdsComparison {
  std::size_t compared = 0;  ///< entries whose value was compared
  std::size_t refused = 0;   ///< entries whose expected abort was checked
  std::vector<std::string> mismatches;
};
EdsComparison CompareWithEds(BusMaster& master, std::uint8_t node_id, const EdsContents& eds);

}  // namespace canfleet::system_test
