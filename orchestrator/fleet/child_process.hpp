#pragma once
/// @file Starting a node process: fork + exec with its output in a log file, tied to the
/// orchestrator's life so that no node outlives it (Linux PR_SET_PDEATHSIG), even after SIGKILL.

#include <sys/types.h>

#include <filesystem>
#include <string>
#include <vector>

namespace canfleet::fleet {

struct LaunchSpec {
  std::filesystem::path binary;
  std::vector<std::string> args;   ///< without argv[0]
  std::filesystem::path log_file;  ///< stdout and stderr, appended
};

/// Starts the process; returns its pid. The child gets SIGTERM when the calling thread ends, so
/// call it from the thread that lives as long as the fleet (the event loop's).
/// @throws std::system_error when fork fails or the log file cannot be opened.
pid_t SpawnChild(const LaunchSpec& spec);

/// "exit code 3", "signal 9 (Killed)".
std::string DescribeWaitStatus(int status);

/// The command line as a shell would show it, for logs.
std::string CommandLine(const LaunchSpec& spec);

}  // namespace canfleet::fleet
