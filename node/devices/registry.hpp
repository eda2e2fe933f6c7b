#pragma once
/// @file The catalog of variants `canfleet-node --device NAME` can run: one data-only entry per
/// product holding its static facts (name, summary, CAN ports, the manual's factory node-ID and bit
/// rate, its EDS and its simulated signals) and how to create its behaviour. canfleet-node, the
/// topology loader and the CLI all read these entries, so each fact is stated once. Adding a
/// variant: its folder (see README.md) and one entry in registry.cpp.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "node/canopen/od/object_dictionary.hpp"
#include "node/devices/device.hpp"
#include "node/devices/embedded_eds.hpp"

namespace canfleet::devices {

struct DeviceInfo {
  std::string_view name;     ///< the --device value
  std::string_view summary;  ///< one line for --list-devices
  std::size_t ports = 1;     ///< CAN ports of the product (the data logger has 2)
  /// The node-ID and bit rate the product leaves the factory with (its manual). The node-ID is used
  /// when a topology or the command line names none; the bit rate is the stack's until the node is
  /// commissioned for the bus it is plugged into (node/process/bit_rate_commissioning.hpp), unless
  /// LSS stored another.
  std::uint8_t factory_node_id = 127;
  std::uint32_t factory_bit_rate_kbit = 125;
  std::string_view eds_file_name;         ///< "quad-controller.eds", for messages and --write-eds
  EmbeddedEds (*eds)();                   ///< the EDS generated from the variant's dictionary table
  void (*declare_signals)(SimulatedIo&);  ///< declares the simulated I/O into an empty SimulatedIo
  std::unique_ptr<Device> (*create)(const DeviceOptions&);
};

/// Every variant, in listing order.
std::span<const DeviceInfo> Devices();
/// The variant called `name`, or null.
const DeviceInfo* FindDevice(std::string_view name);
/// --list-devices: one line per variant ("quad-controller  1 port   id 127 @ 125 kbit/s  Axiomatic ...").
std::string ListDevices();
/// The known names, comma separated, for messages.
std::string KnownDeviceNames();
/// "unknown device \"quad\" (nearest: quad-controller; known: ...)".
std::string UnknownDevice(std::string_view name);

/// A variant's simulated signals without creating the device (topology checks).
std::unique_ptr<SimulatedIo> SignalsOf(const DeviceInfo& info);

/// The dictionary of one port of a variant: its own EDS, or `eds` (a user's copy) when given.
/// @throws canopen::EdsError
canopen::ObjectDictionary VariantDictionary(const DeviceInfo& info, const std::filesystem::path& eds = {});

/// CiA 305 table 0 index of a bit rate (1000 → 0, 125 → 4, 10 → 8); nullopt if it has none.
std::optional<std::uint8_t> BitTimingIndexOf(std::uint32_t kbit);

/// What the command line asked for.
struct DeviceSelection {
  std::string device;         ///< --device; empty = none
  std::filesystem::path eds;  ///< --eds; with a device it replaces the variant's own EDS
};

/// The device to run: the named variant, or with no name the generic slave of `eds`.
/// @throws std::invalid_argument for an unknown name (the message lists the known ones) or when
///         neither a device nor an EDS is given.
std::unique_ptr<Device> MakeDevice(const DeviceSelection& selection);

}  // namespace canfleet::devices
