#pragma once
/// @file System-test helpers: a child process with its stdin and stdout on pipes (stdout read
/// line by line, drained continuously), free TCP ports, short temporary directories, and polling a condition
/// with a generous deadline (never a fixed sleep, never a short bound).

#include <sys/types.h>

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace canfleet::system_test {

/// How long to wait for anything that should happen "soon": generous, so a loaded CI machine
/// does not fail a correct program.
inline constexpr std::chrono::seconds kPatience{10};

/// Calls `condition` every few milliseconds until it is true or `timeout` passes.
bool WaitUntil(const std::function<bool()>& condition, std::chrono::milliseconds timeout = kPatience);

/// A port that was free a moment ago (bound to 127.0.0.1:0 and released). Callers that bind it
/// themselves later retry with another on EADDRINUSE.
std::uint16_t FreeTcpPort();

/// A fresh directory under /tmp with a short path (Unix socket paths are limited to 107 bytes);
/// removed with its contents on destruction.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::string& path() const { return path_; }
  std::string File(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
};

/// A child process. stdin and stdout are pipes; stderr goes to `stderr_path` (appended) so a
/// failing test can show the child's log. Destruction kills (SIGKILL) and reaps it.
///
/// A thread of its own reads stdout as the child writes it. A child whose stdout is read only when
/// the test looks would block in write() once the pipe's 64 KiB are full: an orchestrator logging
/// at debug level, polled by a test through the CLI, stopped answering that way (every request it
/// logs fills the pipe a little) until the test's next look at its output.
class ChildProcess {
 public:
  ChildProcess(std::vector<std::string> argv, std::string stderr_path);
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  pid_t pid() const { return pid_; }

  /// Writes `line` and a newline to the child's stdin.
  void WriteLine(const std::string& line);

  /// Reads stdout until a line satisfies `match` (lines read before are kept too); returns it,
  /// or nullopt after `timeout` or when stdout closes.
  std::optional<std::string> WaitForLine(const std::function<bool(const std::string&)>& match,
                                         std::chrono::milliseconds timeout = kPatience);
  std::optional<std::string> WaitForPrefix(const std::string& prefix,
                                           std::chrono::milliseconds timeout = kPatience);
  /// Every stdout line read so far (a copy: the reader thread appends to the original).
  std::vector<std::string> Lines() const;
  /// Returns once what stdout has ready now is in Lines() (the reader thread drains it anyway;
  /// this is for a caller that wants the output written so far, e.g. after the child exited).
  void Poll();

  void Signal(int signal);
  /// Waits for the exit; returns the exit status (128 + signal when killed), or nullopt on timeout.
  std::optional<int> Wait(std::chrono::milliseconds timeout = kPatience);
  bool Running();

  /// The child's stderr so far.
  std::string Log() const;

 private:
  /// The reader thread: appends stdout's lines until it closes or Stop().
  void ReadStdout();
  void StopReader();

  pid_t pid_ = -1;
  int stdin_fd_ = -1;
  int stdout_fd_ = -1;
  std::string stderr_path_;
  std::optional<int> status_;

  mutable std::mutex mutex_;           ///< guards the members below
  std::condition_variable new_lines_;  ///< a line arrived, or stdout closed
  std::vector<std::string> lines_;
  bool stdout_closed_ = false;
  bool stopping_ = false;
  bool in_flight_ = false;   ///< the reader holds bytes it has not appended yet
  std::size_t scanned_ = 0;  ///< lines already offered to WaitForLine's matcher
  std::thread reader_;
};

/// A connected stream socket to a broker endpoint (tcp://... or unix://...), for tests that speak
/// the protocol by hand. Blocking, closed on destruction.
class RawConnection {
 public:
  explicit RawConnection(const std::string& endpoint);
  ~RawConnection();
  RawConnection(const RawConnection&) = delete;
  RawConnection& operator=(const RawConnection&) = delete;

  bool connected() const { return fd_ >= 0; }
  /// Sends all bytes (false if the peer has gone).
  bool Send(const std::string& bytes);
  bool Send(const std::vector<std::uint8_t>& bytes);
  /// Reads until the peer closes the connection or `timeout` passes; returns what was read and
  /// whether the close was seen.
  struct ReadResult {
    std::vector<std::uint8_t> bytes;
    bool closed = false;
  };
  ReadResult ReadUntilClosed(std::chrono::milliseconds timeout = kPatience);
  /// Reads at least `n` bytes (or until closed/timeout).
  ReadResult ReadAtLeast(std::size_t n, std::chrono::milliseconds timeout = kPatience);

 private:
  int fd_ = -1;
};

}  // namespace canfleet::system_test
