#pragma once
/// @file One emulated CANopen node: a Device, its object dictionaries and one CanopenStack per CAN
/// port, built in the order the Device interface describes. This is all the node process's main
/// needs besides its ports and its event loop:
///
///   auto device = devices::MakeDevice({.device = "quad-controller"});
///   devices::DeviceNode node(std::move(device), scheduler, {&port}, settings);
///   node.Start();   // boot-up frame; then run the event loop

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "bus/bus_port.hpp"
#include "clock/scheduler.hpp"
#include "node/canopen/stack/canopen_stack.hpp"
#include "node/devices/device.hpp"
#include "node/devices/device_port.hpp"

namespace canfleet::devices {

/// Per-port settings from the command line or the topology file.
struct PortSettings {
  /// 1..127, or kUnconfiguredNodeId (LSS only until a master assigns one).
  std::uint8_t node_id = canopen::kUnconfiguredNodeId;
  /// CiA 305 table 0 index (4 = 125 kbit/s).
  std::uint8_t bit_timing_index = 4;
};

struct NodeSettings {
  /// One per device port; missing entries take the defaults above.
  std::vector<PortSettings> ports;
  /// Stored parameters (1010h) and LSS configuration; empty = nothing persists. A device with
  /// several ports keeps port p's files in `state_dir/port<p+1>`.
  std::filesystem::path state_dir;
  /// Replaces 1018h sub 4 (and its default): each unit of a fleet has its own serial number, so
  /// that LSS can tell identical products apart.
  std::optional<std::uint32_t> serial_number;
  /// Called after the device's own hooks (e.g. the node process logs storage issues).
  canopen::StackHooks hooks;
};

class DeviceNode {
 public:
  /// Builds the dictionaries, the stacks (stack i on ports[i]) and attaches the device.
  /// @throws std::invalid_argument when ports.size() differs from device->PortCount();
  ///         canopen::EdsError / std::logic_error from Build and Attach.
  DeviceNode(std::unique_ptr<Device> device, Scheduler& scheduler, std::vector<BusPort*> ports,
             NodeSettings settings);
  ~DeviceNode();
  DeviceNode(const DeviceNode&) = delete;
  DeviceNode& operator=(const DeviceNode&) = delete;

  /// Power-on of every stack, port order: parameters restored, reset application, boot-up.
  void Start();

  /// Port `port` (0-based) switched its bit rate to `kbit` (LSS activate bit timing, the device's
  /// bit-rate object at reset): `applied` says whether the bus port followed (BusPort::SetBitRate;
  /// false on SocketCAN, whose rate is the interface's).
  using BitRateReport = std::function<void(std::size_t port, std::uint32_t kbit, bool applied)>;
  /// Tells `report` of every switch from now on.
  void OnBitRate(BitRateReport report) { on_bit_rate_ = std::move(report); }

  Device& device() { return *device_; }
  SimulatedIo& io() { return device_->io(); }
  std::size_t PortCount() const { return stacks_.size(); }
  canopen::CanopenStack& stack(std::size_t port = 0) { return *stacks_.at(port); }
  canopen::ObjectDictionary& od(std::size_t port = 0) { return *dictionaries_.at(port); }
  /// The 11-bit identifiers port `port` listens to now (canopen::CanopenStack::ListenedIds), or
  /// nullopt when the device itself watches every frame of the port.
  std::optional<std::vector<std::uint32_t>> ListenedIds(std::size_t port) const {
    if (device_ports_.at(port)->Observed()) return std::nullopt;
    return stacks_.at(port)->ListenedIds();
  }
  /// Of those, the heartbeats answered with nothing at once (canopen::CanopenStack::PassiveIds).
  std::vector<std::pair<std::uint32_t, Duration>> PassiveIds(std::size_t port) const {
    if (device_ports_.at(port)->Observed()) return {};
    return stacks_.at(port)->PassiveIds();
  }

 private:
  void ShareObjects();
  void ForwardSharedStorage();

  // Destroyed in reverse order: the device (its timers and blocks) before the stacks, the stacks
  // before the dictionaries they hook into.
  std::vector<std::unique_ptr<DevicePort>> device_ports_;
  std::vector<std::unique_ptr<canopen::ObjectDictionary>> dictionaries_;
  std::vector<std::unique_ptr<canopen::CanopenStack>> stacks_;
  std::unique_ptr<Device> device_;
  BitRateReport on_bit_rate_;
};

/// Runs `first` then `second` for every hook either sets.
canopen::StackHooks ChainHooks(canopen::StackHooks first, canopen::StackHooks second);

}  // namespace canfleet::devices
