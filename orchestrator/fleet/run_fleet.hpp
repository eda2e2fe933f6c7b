#pragma once
/// @file `canfleet up`: load a topology, start the orchestrator (broker, node processes, control
/// API) and run until SIGINT/SIGTERM or a Shutdown request; then stop every node process.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include "orchestrator/fleet/fleet_time.hpp"

#include "orchestrator/topology/canfleet_topology.pb.h"
#include "telemetry/dds.hpp"

namespace canfleet::fleet {

struct UpOptions {
  std::filesystem::path topology;             ///< the topology file
  std::optional<std::string> control;         ///< overrides Orchestrator.control (e.g. tcp://127.0.0.1:0)
  std::optional<std::string> listen;          ///< overrides Orchestrator.listen (one broker endpoint)
  std::string socketcand_bind = "127.0.0.1";  ///< address the buses' socketcand endpoints listen on
  /// The fleet's token (bus/wire/auth_token.hpp): needed, and then required of every client, when
  /// the control API or the broker listens beyond loopback. Empty: loopback only.
  std::string token{};
  /// Where captures asked for over the control API go (a relative file) and may go (besides the
  /// state root). Empty: <state root>/captures.
  std::filesystem::path capture_dir{};
  std::filesystem::path node_binary;  ///< canfleet-node; empty: beside this executable, then PATH
  std::filesystem::path ready_file;   ///< once every node booted: "control <endpoint>\nbroker <endpoint>\n"
  std::string log_level = "info";
  bool no_start = false;  ///< load and start the buses, but no node processes
  /// Virtual time: from the moment the fleet is ready, time runs only inside a client's
  /// ClockAdvance (TimeConductor::Drive).
  bool driven = false;
  /// --web [ADDR:]PORT: also serve the fleet in a browser (a `canfleet web` child process reading
  /// the fleet's DDS domain, its actions going to this fleet's control API); empty: no.
  std::string web;
  bool telemetry = true;  ///< BusStats and FaultEvents on DDS
  /// Where the orchestrator publishes (canfleet up's --dds-* options); also passed to its nodes.
  telemetry::DdsOptions dds;
  TimeOverride time;  ///< --time / --speed; empty: the topology's time
  /// --state-dir: the fleet's state root (node state and logs) instead of the topology's
  /// state_root; nodes whose state_dir was the default follow it (as `canfleet test` does).
  std::optional<std::filesystem::path> state_root;
  /// --seed: seeds the faults that give no seed of their own (overrides the topology's time.seed).
  std::optional<std::uint64_t> seed;
};

/// The node processes of a fleet of `spec`: one per node, started by the fleet or (external)
/// elsewhere; in virtual time the fleet's time starts once all of them joined.
std::size_t NodeProcesses(const topology::Topology& spec);

/// canfleet-node: `asked` when given (it must be executable), else beside this executable, else on
/// PATH. Throws std::runtime_error naming what was tried.
std::filesystem::path FindNodeBinary(const std::filesystem::path& asked);

/// Runs the fleet in the calling thread. Returns the process exit code: 0 after a clean
/// shutdown, 2 when the topology is refused (the message names file, line and field) or an
/// endpoint cannot be bound.
int RunFleet(const UpOptions& options);

}  // namespace canfleet::fleet
