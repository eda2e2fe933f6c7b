#include "node/devices/registry.hpp"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <vector>

#include "node/devices/datalogger_tc_analog/datalogger.hpp"
#include "node/devices/datalogger_tc_analog/datalogger_io.hpp"
#include "node/devices/eds_dictionary.hpp"
#include "node/devices/encoder_dual_valve/encoder_io.hpp"
#include "node/devices/encoder_dual_valve/encoder_valve_controller.hpp"
#include "node/devices/generic_device.hpp"
#include "node/devices/power_supply_24v_350w/power_supply.hpp"
#include "node/devices/quad_controller/quad_controller.hpp"
#include "node/devices/valve_12in12out/valve_controller.hpp"
#include "node/devices/valve_12in12out/valve_io.hpp"
#include "vocabulary/nearest_names.hpp"

namespace canfleet::devices {
namespace {

template <typename T>
std::unique_ptr<Device> Create(const DeviceOptions& options) {
  return std::make_unique<T>(options);
}

}  // namespace

std::span<const DeviceInfo> Devices() {
  static const std::array<DeviceInfo, 5> devices = {{
      {.name = QuadController::kName,
       .summary = QuadController::kSummary,
       .ports = 1,
       // AX020506 states no factory node-ID or bit rate (§2.1: "set by LSS"); the family's four
       // other manuals all ship at 127 and 125 kbit/s (valve §3.1, power supply §2.1, encoder
       // C3-1.1, data logger §3.1), so the Quad does too (quad_controller/README.md).
       .factory_node_id = 127,
       .factory_bit_rate_kbit = 125,
       .eds_file_name = "quad-controller.eds",
       .eds = QuadControllerEds,
       .declare_signals = [](SimulatedIo& io) { quad::QuadIo declared(io); },
       .create = Create<QuadController>},
      {.name = ValveController::kName,
       .summary = ValveController::kSummary,
       .ports = 1,
       .factory_node_id = 127,  // UMAX020411A §3.1: node-ID 127, 125 kbit/s
       .factory_bit_rate_kbit = 125,
       .eds_file_name = "valve-12in12out.eds",
       .eds = ValveEds,
       .declare_signals = [](SimulatedIo& io) { valve::DeclareValveSignals(io); },
       .create = Create<ValveController>},
      {.name = EncoderValveController::kName,
       .summary = EncoderValveController::kSummary,
       .ports = 1,
       .factory_node_id = 127,  // AX023241 chapter 3 §1.1: node-ID 127, 125 kbit/s
       .factory_bit_rate_kbit = 125,
       .eds_file_name = "encoder-dual-valve.eds",
       .eds = EncoderEds,
       .declare_signals = [](SimulatedIo& io) { encoder::DeclareEncoderSignals(io); },
       .create = Create<EncoderValveController>},
      {.name = DataLogger::kName,
       .summary = DataLogger::kSummary,
       .ports = 2,
       // UMAX181001 §3.1: one factory node-ID and bit rate, the same on both ports (separate buses).
       .factory_node_id = 127,
       .factory_bit_rate_kbit = 125,
       .eds_file_name = "datalogger-tc-analog.eds",
       .eds = DataLoggerEds,
       .declare_signals = datalogger::DeclareDataLoggerSignals,
       .create = Create<DataLogger>},
      {.name = PowerSupply::kName,
       .summary = PowerSupply::kSummary,
       .ports = 1,
       .factory_node_id = PowerSupply::kFactoryNodeId,  // UMAX080311 §2.1
       .factory_bit_rate_kbit = PowerSupply::kFactoryBitRateKbit,
       .eds_file_name = PowerSupply::kEdsFileName,
       .eds = PowerSupplyEds,
       .declare_signals = PowerSupply::DeclareSignals,
       .create = Create<PowerSupply>},
  }};
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
    std::string factory = "id " + std::to_string(info.factory_node_id) + " @ " +
                          std::to_string(info.factory_bit_rate_kbit) + " kbit/s";
    out += factory + std::string(factory.size() < 22 ? 22 - factory.size() : 1, ' ');
    out += std::string(info.summary) + "\n";
  }
  return out;
}

std::string KnownDeviceNames() {
  std::string known;
  for (const DeviceInfo& d : Devices())
    known += (known.empty() ? "" : ", ") + std::string(d.name);
  return known;
}

std::string UnknownDevice(std::string_view name) {
  std::vector<std::string> names;
  for (const DeviceInfo& d : Devices())
    names.emplace_back(d.name);
  std::string out = "unknown device \"" + std::string(name) + "\" (";
  if (const auto nearest = NearestNames(name, names); !nearest.empty())
    out += "nearest: " + JoinNames(nearest) + "; ";
  return out + "known: " + KnownDeviceNames() + ")";
}

std::unique_ptr<SimulatedIo> SignalsOf(const DeviceInfo& info) {
  auto io = std::make_unique<SimulatedIo>();
  info.declare_signals(*io);
  return io;
}

canopen::ObjectDictionary VariantDictionary(const DeviceInfo& info, const std::filesystem::path& eds) {
  return LoadVariantDictionary(info.eds(), info.eds_file_name, eds);
}

std::optional<std::uint8_t> BitTimingIndexOf(std::uint32_t kbit) {
  // CiA 305 §5.5 table 0 (the LSS bit timing table); index 5 is reserved (100 kbit/s in CiA 301).
  static constexpr std::array<std::uint32_t, 9> kTable = {1000, 800, 500, 250, 125, 100, 50, 20, 10};
  for (std::size_t i = 0; i < kTable.size(); ++i) {
    if (kTable[i] == kbit && i != 5) return static_cast<std::uint8_t>(i);
  }
  return std::nullopt;
}

std::unique_ptr<Device> MakeDevice(const DeviceSelection& selection) {
  if (selection.device.empty()) {
    if (selection.eds.empty()) throw std::invalid_argument("give --device NAME or --eds FILE");
    return std::make_unique<GenericDevice>(selection.eds);
  }
  const DeviceInfo* info = FindDevice(selection.device);
  if (!info) {
    throw std::invalid_argument(UnknownDevice(selection.device));
  }
  return info->create(DeviceOptions{.eds = selection.eds, .ports = info->ports});
}

}  // namespace canfleet::devices
