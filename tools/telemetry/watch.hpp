#pragma once
/// @file `canfleet watch`: a stream of fleet events, one per line (text or JSON lines).

#include <CLI/CLI.hpp>

#include <chrono>
#include <ostream>
#include <set>
#include <string>

#include "telemetry/dds.hpp"
#include "tools/telemetry/fleet_view.hpp"

namespace canfleet::tools {

struct WatchOptions {
  telemetry::DdsOptions dds{};
  bool json = false;
  std::string bus{};  ///< only this bus; empty = all
  int node = -1;      ///< only this node-id; -1 = all
  /// Event kinds to print; empty = all but "seen" (every node's first status is not news).
  std::set<EventKind> kinds{};
  /// Print events that happened before watch started (delivered from DDS history), flagged.
  bool history = true;
  /// Exit with 0 after this many events (0 = never).
  int count = 0;
  /// Exit after this long (0 = never); exit code 0, or 2 if `count` events were not seen by then.
  std::chrono::milliseconds timeout{0};
  std::ostream* out = nullptr;  ///< default std::cout
};

void AddWatchOptions(CLI::App& app, WatchOptions& options);

/// True if `event` passes the options' bus/node/kind/history filters.
bool Selected(const FleetEvent& event, const WatchOptions& options);

/// Runs watch; returns the process exit code. Throws DdsError if DDS cannot start.
int RunWatch(const WatchOptions& options);

}  // namespace canfleet::tools
