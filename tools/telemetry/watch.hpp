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
  /// Also print events that happened before watch started (delivered from DDS history), flagged
  /// "[history]" / "replay":true. Off by default: a user asking what happens now does not want the
  /// boot-time EMCYs of an hour ago first (issue 29).
  bool history = false;
  /// Exit with 0 after this many events (0 = never).
  int count = 0;
  /// Exit after this long (0 = never); exit code 0, or 1 if `count` events were not seen by then
  /// (2 stays the code of bad arguments, README.md "The canfleet command line").
  std::chrono::milliseconds timeout{0};
  /// After this long without any node or bus seen, say on stderr where watch looked and what to do
  /// (0 = never). Nothing seen at all is a configuration mismatch far more often than a quiet fleet.
  std::chrono::milliseconds hint_after{std::chrono::seconds(5)};
  std::ostream* err = nullptr;  ///< default std::cerr
  std::ostream* out = nullptr;  ///< default std::cout
};

void AddWatchOptions(CLI::App& app, WatchOptions& options);

/// True if `event` passes the options' bus/node/kind/history filters.
bool Selected(const FleetEvent& event, const WatchOptions& options);

/// Runs watch; returns the process exit code. Throws DdsError if DDS cannot start.
int RunWatch(const WatchOptions& options);

}  // namespace canfleet::tools
