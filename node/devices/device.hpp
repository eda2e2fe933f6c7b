#pragma once
/// @file The Device interface (design decision 4: a device is data plus behaviour). A variant
/// supplies its object dictionary (from its EDS, the file users load into their own master), the
/// way its stack(s) differ from plain CiA 301 (error encoding, start in operational, EMCY history,
/// life-cycle hooks), and its function blocks, which attach to the dictionary through hooks and
/// run on ticks of the node's Scheduler. It declares its simulated I/O (simulated_io.hpp) when
/// constructed. DeviceNode (device_node.hpp) builds the whole node from a Device.
///
/// Life cycle, driven by DeviceNode:
///   1. Build(port, od)            for every port: fill the dictionary (EDS or code)
///   2. ConfigureStack(port, setup) for every port: adjust the stack's options, hooks, policy
///   3. the stacks are built on the dictionaries
///   4. Attach(context)            install hooks on the dictionaries, create blocks, start ticks
///   5. DeviceNode::Start()        power-on of every stack (reset application → hooks → boot)

#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>
#include <string_view>
#include <vector>

#include "clock/scheduler.hpp"
#include "node/canopen/stack/canopen_stack.hpp"
#include "node/canopen/stack/error_policy.hpp"
#include "node/devices/device_port.hpp"
#include "node/devices/simulated_io.hpp"

namespace canfleet::devices {

/// What a variant is created with.
struct DeviceOptions {
  /// Replaces the variant's own EDS (a user-edited copy); empty = the EDS shipped with the variant.
  std::filesystem::path eds;
  /// CAN ports of the product, from its catalog entry (registry.hpp), the one place that says it.
  std::size_t ports = 1;
};

/// How the stack of one port will be built. DeviceNode fills the node-level options (node-ID,
/// state directory, bit timing); the device adds what its manual says.
struct StackSetup {
  canopen::StackOptions options;
  canopen::StackHooks hooks;
  /// Null: CiA 301 encoding of communication errors.
  std::shared_ptr<const canopen::ErrorPolicy> policy;
};

/// What a device attaches to: the clock, one stack per port (stack i runs on port i) and the
/// ports themselves, through which a device may observe frames, mute or send (device_port.hpp).
struct DeviceContext {
  Scheduler& scheduler;
  std::vector<canopen::CanopenStack*> stacks;
  std::vector<DevicePort*> ports;
};

class Device {
 public:
  virtual ~Device() = default;

  /// The --device name ("quad-controller"); "generic" for an EDS-only node.
  virtual std::string_view Name() const = 0;
  /// CAN ports of the product: 1, or 2 for the data logger (one stack per port, shared
  /// application objects: see SharedObjects()). Set from the catalog entry at construction.
  std::size_t PortCount() const { return ports_; }

  /// A range of objects of a multi-port device that are one set for the whole device (the data
  /// logger's application objects, 2000h-FFFFh): port 1's dictionary owns them and every other
  /// port's dictionary borrows them (ObjectDictionary::Borrow). A store (1010h) or restore (1011h)
  /// on any port covers them once, through port 1's parameter store. nullopt: nothing shared.
  struct ObjectRange {
    std::uint16_t first;
    std::uint16_t last;
  };
  virtual std::optional<ObjectRange> SharedObjects() const { return std::nullopt; }

  /// Fills the dictionary of port `port` with every object of the device (communication and
  /// application area). Runs before any stack exists; install no hooks here.
  /// @throws canopen::EdsError or std::runtime_error (an unreadable EDS is an edge).
  virtual void Build(std::size_t port, canopen::ObjectDictionary& od) = 0;

  /// Adjusts the stack of port `port` before it is built: ErrorPolicy, EmcyOptions,
  /// start_operational, StackHooks (the hooks may capture `this`: the device outlives its stacks'
  /// use of them).
  virtual void ConfigureStack(std::size_t port, StackSetup& setup) {
    (void)port;
    (void)setup;
  }

  /// The stacks exist: resolve objects, install validators/listeners/read hooks, create the
  /// function blocks and start their ticks.
  /// @throws std::logic_error when the dictionary lacks an object the blocks need.
  virtual void Attach(DeviceContext& context) = 0;

  /// The device's simulated inputs and outputs.
  SimulatedIo& io() { return io_; }
  const SimulatedIo& io() const { return io_; }

 protected:
  explicit Device(std::size_t ports = 1) : ports_(ports) {}

  SimulatedIo io_;

 private:
  std::size_t ports_;
};

}  // namespace canfleet::devices
