#pragma once
/// @file The generic node (design decision 4): `canfleet-node --eds FILE` without --device runs a
/// CiA 301 slave whose dictionary is exactly the EDS's, on the standard stack, with no function
/// blocks and no simulated I/O. Values change only when the network writes them.

#include <filesystem>
#include <string_view>

#include "node/devices/device.hpp"

namespace canfleet::devices {

class GenericDevice final : public Device {
 public:
  /// @param eds an EDS or DCF file (read when the node is built)
  explicit GenericDevice(std::filesystem::path eds) : eds_(std::move(eds)) {}

  std::string_view Name() const override { return "generic"; }
  void Build(std::size_t port, canopen::ObjectDictionary& od) override;
  void Attach(DeviceContext& context) override { (void)context; }

  const std::filesystem::path& eds() const { return eds_; }

 private:
  std::filesystem::path eds_;
};

}  // namespace canfleet::devices
