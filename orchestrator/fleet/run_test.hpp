#pragma once
/// @file `canfleet test FILE...` (issue 21): for each scenario file, start its fleet (broker, node
/// processes) on private endpoints, run its scenario, print one line per expectation as it is
/// decided, stop the fleet; then a summary line and, when asked, a JUnit XML report.
///
/// Exit code: 0 when every expectation of every file passed; 1 when one failed or was not judged,
/// or a fleet did not start (an error, never a pass); 2 for bad arguments or a file that is
/// refused (the message names file, line and field).

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>
#include "orchestrator/fleet/fleet_time.hpp"

#include "telemetry/dds.hpp"

namespace canfleet::fleet {

struct TestOptions {
  std::vector<std::filesystem::path> files;
  std::filesystem::path junit;        ///< empty: no JUnit report
  TimeOverride time;                  ///< --time / --speed; empty: each topology's
  std::optional<std::uint64_t> seed;  ///< recorded in the report; seeds faults that give none
  /// Each bus of each fleet captured in candump log format to <capture>/<file stem>-<bus>.log
  /// (from before the first node starts). Empty: no capture.
  std::filesystem::path capture;
  std::filesystem::path node_binary;  ///< canfleet-node; empty: FindNodeBinary's search
  /// Where each fleet keeps its state and logs (<state_dir>/<n>-<topology name>/, the
  /// orchestrator's log is orchestrator.log there). Empty: a fresh folder under the system's
  /// temporary folder, removed when every expectation passed, kept (and named) otherwise.
  std::filesystem::path state_dir;
  std::chrono::milliseconds ready_timeout{60'000};  ///< a fleet not ready by then did not start
  std::string log_level = "info";                   ///< of the orchestrator's log file
  bool telemetry = false;  ///< nodes and buses publish over DDS (off: test fleets are private)
  telemetry::DdsOptions dds;
};

/// Runs every file in turn. Lines go to `out`.
int RunTests(const TestOptions& options, std::ostream& out);

}  // namespace canfleet::fleet
