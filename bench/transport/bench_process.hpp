#pragma once
// A child process of the benchmark driver: stdin and stdout on pipes, stderr inherited.

#include <sys/types.h>

#include <chrono>
#include <optional>
#include <string>
#include <vector>

namespace canfleet::bench {

class BenchProcess {
 public:
  explicit BenchProcess(std::vector<std::string> argv);
  ~BenchProcess();  // SIGKILL + reap if still running
  BenchProcess(const BenchProcess&) = delete;
  BenchProcess& operator=(const BenchProcess&) = delete;

  pid_t pid() const { return pid_; }
  void WriteLine(const std::string& line);
  /// The next stdout line, or nullopt on timeout or end of output.
  std::optional<std::string> ReadLine(std::chrono::milliseconds timeout);
  /// Sends SIGTERM and waits up to `timeout`; SIGKILL after that.
  void Stop(std::chrono::milliseconds timeout = std::chrono::seconds(5));
  /// User + system CPU time consumed so far (from /proc/<pid>/stat).
  std::chrono::duration<double> CpuTime() const;

 private:
  pid_t pid_ = -1;
  int stdin_fd_ = -1;
  int stdout_fd_ = -1;
  std::string buffer_;
  bool reaped_ = false;
};

/// CLOCK_MONOTONIC in ns (std::chrono::steady_clock on Linux): the same time line in every
/// process of the host, so a frame can carry its send time to another process.
std::int64_t MonotonicNs();

}  // namespace canfleet::bench
