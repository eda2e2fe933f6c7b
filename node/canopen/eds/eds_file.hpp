#pragma once
/// @file The contents of a CiA 306 (v1.3) EDS or DCF: the file-level sections kept for writing the
/// file back, and the object dictionary it describes.

#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "node/canopen/od/object_dictionary.hpp"

namespace canfleet::canopen {

/// Which kind of file WriteEds produces. A DCF (CiA 306 §5) is an EDS plus the configured values
/// (ParameterValue) and the [DeviceComissioning] section.
enum class EdsFormat : std::uint8_t { kEds, kDcf };

/// CiA 306 §4.3 [FileInfo]. Dates and times are kept as text in the file's spelling
/// (CreationTime hh:mm(AM|PM), CreationDate mm-dd-yyyy); empty means absent.
struct FileInfo {
  std::string file_name;
  std::uint8_t file_version = 1;
  std::uint8_t file_revision = 0;
  std::string eds_version = "4.0";
  std::string description;
  std::string creation_time;
  std::string creation_date;
  std::string created_by;
  std::string modification_time;
  std::string modification_date;
  std::string modified_by;
  std::string last_eds;  ///< DCF only: the EDS this DCF was made from (CiA 306 §5)

  bool operator==(const FileInfo&) const = default;
};

/// CiA 306 §4.4 [DeviceInfo].
struct DeviceInfo {
  std::string vendor_name;
  std::uint32_t vendor_number = 0;  ///< the 1018h sub1 value
  std::string product_name;
  std::uint32_t product_number = 0;   ///< the 1018h sub2 value
  std::uint32_t revision_number = 0;  ///< the 1018h sub3 value
  std::string order_code;
  std::set<std::uint16_t> baud_rates_kbit;  ///< from BaudRate_10 ... BaudRate_1000 = 1
  bool simple_boot_up_master = false;
  bool simple_boot_up_slave = false;
  std::uint8_t granularity = 0;  ///< 0..64: PDO mapping granularity in bits (0 = no mapping)
  std::uint8_t dynamic_channels_supported = 0;
  bool group_messaging = false;
  std::uint16_t nr_of_rx_pdo = 0;
  std::uint16_t nr_of_tx_pdo = 0;
  bool lss_supported = false;
  std::optional<std::uint8_t> compact_pdo;

  bool operator==(const DeviceInfo&) const = default;
};

/// The CiA 306 §5 [DeviceComissioning] keys other than NodeID and Baudrate (DCF only).
struct DeviceCommissioning {
  std::string node_name;
  std::optional<std::uint32_t> net_number;
  std::string network_name;
  std::optional<bool> canopen_manager;
  std::optional<std::uint32_t> lss_serial_number;

  bool operator==(const DeviceCommissioning&) const = default;
};

/// Node-relative limits ("LowLimit=$NODEID+0x180"). SubObject has no flag for them, so the reader
/// keeps the constant part in the SubObject's limit and records here which limits add the node-ID.
struct NodeIdLimits {
  bool low = false;
  bool high = false;

  bool operator==(const NodeIdLimits&) const = default;
};

/// A whole EDS or DCF.
struct EdsFile {
  FileInfo file_info;
  DeviceInfo device_info;
  /// CiA 306 §4.5 [DummyUsage]: bit n set = the data type with index n may be mapped as a dummy.
  std::uint32_t dummy_usage = 0;
  std::vector<std::string> comments;               ///< CiA 306 [Comments] Line1..LineN
  std::optional<std::uint8_t> dcf_node_id;         ///< [DeviceComissioning] NodeID, 1..127
  std::optional<std::uint32_t> dcf_baudrate_kbit;  ///< [DeviceComissioning] Baudrate
  DeviceCommissioning commissioning;               ///< the other [DeviceComissioning] keys
  /// Keyed by (index, sub-index); only sub-objects with a node-relative limit appear.
  std::map<std::pair<std::uint16_t, std::uint8_t>, NodeIdLimits> node_id_limits;
  /// Defaults hold the constant part of "$NODEID+x" (SubObject::default_adds_node_id). Current
  /// values are the DCF ParameterValue if given, else the default with the DCF NodeID (if any)
  /// applied.
  ObjectDictionary od;
};

}  // namespace canfleet::canopen
