#pragma once
/// @file canfleet-node's telemetry (issue 7): the DeviceNode's state published over DDS through
/// telemetry::NodeTelemetry, one publisher per CAN port (keyed by that port's bus and node-ID):
///  - NodeStatus: the node's name (--name), NMT state, 1001h, controller state with TEC/REC, 1017h, the 1016h
///  consumers and
///    the PDO counters. Sampled at once on every NMT state change, communication error (every
///    controller state change is one: 8120h/8140h raised or cleared) and EMCY sent, and every
///    period (counters, 1017h written by SDO, errors raised while no EMCY may go out).
///  - IoSnapshot: the device's simulated I/O (devices::SimulatedIo), on every change. A
///    multi-port device publishes its I/O under each port's key. Numbers are published as they
///    are, bools as 0/1, enums as the index of the choice in the signal's declaration; bools and
///    enums carry their word too ("true", "on": IoValue.text, as `canfleet io get` prints them).
///  - Emcy: every EMCY frame a port's stack sent (canopen::Emcy::OnSent), with code, 1001h and the
///    five manufacturer bytes.
/// Everything here runs on the node's event-loop thread; NodeTelemetry only copies the values and
/// writes to DDS from its own thread, so the CAN path never waits for DDS.
///
/// In main:
/// @code
///   node::TelemetrySettings telemetry_settings;               // main(): AddTelemetryOptions(app, ...)
///   auto telemetry = node::StartNodeTelemetry(telemetry_settings, settings, *log);  // before the node
///   node = std::make_unique<devices::DeviceNode>(...);
///   if (telemetry) telemetry->Attach(*node, scheduler, node::BusNames(options), options.name);
///   ...
///   telemetry.reset();                                        // monitors see the node leave
/// @endcode

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "clock/scheduler.hpp"
#include "node/canopen/stack/canopen_stack.hpp"
#include "node/devices/device_node.hpp"
#include "node/process/node_options.hpp"
#include "telemetry/dds.hpp"

namespace spdlog {
class logger;
}

namespace canfleet::node {

/// The node's telemetry settings from its command line.
struct TelemetrySettings {
  bool enabled = true;  ///< --no-telemetry turns it off
  telemetry::DdsOptions dds;
  /// Every port's status and I/O are republished at least this often (and the counters sampled).
  std::chrono::milliseconds period{1000};
};

/// Adds --no-telemetry, --telemetry-period and the DDS options (telemetry/cli_options.hpp:
/// --dds-domain, --dds-config, with their environment fallbacks).
void AddTelemetryOptions(CLI::App& app, TelemetrySettings& settings);

class NodeTelemetryWiring {
 public:
  /// Creates the process's DDS participant. @throws telemetry::DdsError.
  explicit NodeTelemetryWiring(const TelemetrySettings& settings);
  /// Stops sampling and destroys the publishers, which disposes every port's instances (monitors
  /// show the node as left). Does not touch the DeviceNode: hooks and listeners it installed
  /// become no-ops, so the node may be destroyed before or after this.
  ~NodeTelemetryWiring();
  NodeTelemetryWiring(const NodeTelemetryWiring&) = delete;
  NodeTelemetryWiring& operator=(const NodeTelemetryWiring&) = delete;

  /// Stack hooks that resample the status; chain them into devices::NodeSettings::hooks before the
  /// DeviceNode is built (they do nothing until Attach).
  canopen::StackHooks Hooks();

  /// Starts publishing for `node`, whose port p is attached to the bus named `buses[p]`. Call
  /// once, after the node is built, on the event-loop thread. A bus name beyond the IDL's 15
  /// characters is logged and nothing is published (the node runs without telemetry).
  /// @param scheduler the node's scheduler (the periodic sampling timer); must outlive this object.
  /// @param name the node's name (--name, the topology's name under `canfleet up`), published in
  ///        every port's NodeStatus.
  /// @throws std::invalid_argument when `buses` does not name every port.
  void Attach(devices::DeviceNode& node, Scheduler& scheduler, const std::vector<std::string>& buses,
              const std::string& name = "");

  /// Samples every port's status now (the hooks and the timer call this).
  void Sample();
  /// Blocks until everything handed over so far was written to DDS (tests).
  void Flush();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  /// What hooks and listeners hold: points to impl_ until destruction, then null.
  std::shared_ptr<Impl*> handle_;
};

/// The bus name of every port (--bus), in port order.
std::vector<std::string> BusNames(const NodeOptions& options);

/// main's entry point: null when telemetry is disabled, or when DDS cannot start (the reason is
/// logged and the node runs without telemetry: the emulation matters more than its monitoring).
/// Otherwise the wiring, with its hooks already chained into `node_settings.hooks`.
std::unique_ptr<NodeTelemetryWiring> StartNodeTelemetry(const TelemetrySettings& settings,
                                                        devices::NodeSettings& node_settings,
                                                        spdlog::logger& log);

}  // namespace canfleet::node
