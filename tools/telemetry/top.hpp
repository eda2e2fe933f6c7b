#pragma once
/// @file `canfleet top`: a live table of every node of every bus on a DDS domain.

#include <CLI/CLI.hpp>

#include <chrono>
#include <optional>
#include <ostream>
#include <string>

#include "telemetry/dds.hpp"
#include "tools/telemetry/top_format.hpp"

namespace canfleet::tools {

struct TopOptions {
  telemetry::DdsOptions dds{};
  TopFilter filter{};
  SortKey sort = SortKey::kBusNode;
  bool reverse = false;
  std::chrono::milliseconds refresh{500};
  /// Print one frame to the output (no ANSI unless `color`) once the fleet has been discovered.
  bool once = false;
  /// Print this many frames, `refresh` apart, then exit (0: run until `q`/Ctrl-C).
  int iterations = 0;
  /// --once: the longest wait for the fleet; it returns earlier once no new node appeared for 1 s.
  std::chrono::milliseconds wait{5000};
  /// Colors: "auto" (when the output is a terminal), "always", "never".
  std::string color = "auto";
  /// Screen size; 0 = the terminal's (or 132x50 when not a terminal).
  int width = 0;
  int height = 0;
  /// Interactive mode: turn to the next page every this many seconds (0 = only on `n`).
  std::chrono::seconds auto_page{0};
  /// Open on this node's detail view (--node can0:6); --once prints it instead of the table.
  std::optional<NodeKey> node{};
  std::ostream* out = nullptr;  ///< default std::cout
};

/// Registers top's options on a CLI11 (sub)command; the DDS options included.
void AddTopOptions(CLI::App& app, TopOptions& options);

/// Runs top; returns the process exit code. Throws DdsError if DDS cannot start.
int RunTop(const TopOptions& options);

}  // namespace canfleet::tools
