#include "node/devices/registry.hpp"

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "node/devices/generic_device.hpp"
#include "node/devices/quad_controller/quad_controller.hpp"

namespace canfleet::devices {

std::span<const DeviceInfo> Devices() {
  static const std::vector<DeviceInfo> devices = {
      {QuadController::kName, QuadController::kSummary, 1,
       [](const DeviceOptions& options) { return std::make_unique<QuadController>(options); }},
  };
  return devices;
}

const DeviceInfo* FindDevice(std::string_view name) {
  for (const DeviceInfo& info : Devices()) {
    if (info.name == name) return &info;
  }
  return nullptr;
}

std::string ListDevices() {
  std::size_t width = 0;
  for (const DeviceInfo& info : Devices())
    width = std::max(width, info.name.size());
  std::string out;
  for (const DeviceInfo& info : Devices()) {
    out += std::string(info.name);
    out += std::string(width - info.name.size() + 2, ' ');
    out += std::to_string(info.ports) + (info.ports == 1 ? " port   " : " ports  ");
    out += std::string(info.summary) + "\n";
  }
  return out;
}

std::unique_ptr<Device> MakeDevice(const DeviceSelection& selection) {
  if (selection.device.empty()) {
    if (selection.eds.empty()) throw std::invalid_argument("give --device NAME or --eds FILE");
    return std::make_unique<GenericDevice>(selection.eds);
  }
  const DeviceInfo* info = FindDevice(selection.device);
  if (!info) {
    std::string known;
    for (const DeviceInfo& d : Devices())
      known += (known.empty() ? "" : ", ") + std::string(d.name);
    throw std::invalid_argument("unknown device \"" + selection.device + "\" (known: " + known + ")");
  }
  return info->create(DeviceOptions{selection.eds});
}

}  // namespace canfleet::devices
