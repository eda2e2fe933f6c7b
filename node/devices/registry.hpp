#pragma once
/// @file The variants `canfleet-node --device NAME` can run, and the choice between a variant and
/// the generic `--eds FILE` node. Adding a variant: its folder (see README.md), one line in
/// registry.cpp, one dependency in CMakeLists.txt.

#include <cstddef>
#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "node/devices/device.hpp"

namespace canfleet::devices {

struct DeviceInfo {
  std::string_view name;     ///< the --device value
  std::string_view summary;  ///< one line for --list-devices
  std::size_t ports = 1;     ///< CAN ports the node needs
  std::function<std::unique_ptr<Device>(const DeviceOptions&)> create;
};

/// Every variant, in listing order.
std::span<const DeviceInfo> Devices();
/// The variant called `name`, or null.
const DeviceInfo* FindDevice(std::string_view name);
/// --list-devices: one line per variant ("quad-controller  1 port  Axiomatic ...").
std::string ListDevices();

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
