#pragma once
/// @file Keeps the fleet's node processes running: starts them, reaps them (SIGCHLD), restarts a
/// crashed one per its policy with a doubling backoff, and carries out the process faults (kill,
/// restart, power-cycle). Everything runs on the event loop's thread.

#include <sys/types.h>

#include <asio/io_context.hpp>
#include <asio/signal_set.hpp>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>

#include "clock/scheduler.hpp"
#include "orchestrator/fleet/child_process.hpp"
#include "orchestrator/fleet/restart_backoff.hpp"

namespace canfleet::fleet {

struct RestartPolicy {
  bool on_failure = false;         ///< restart after a non-zero exit or a signal
  std::uint32_t max_restarts = 0;  ///< 0 = no limit
  /// First delay, doubled each time up to RestartBackoff::kMaxDelay, and the first again after a
  /// run of RestartBackoff::kStablePeriod (restart_backoff.hpp).
  std::chrono::milliseconds backoff{500};
};

/// What `canfleet status` shows of a process.
struct ProcessView {
  std::string state;   ///< "running", "restarting", "exited", "killed", "stopped"
  std::string detail;  ///< how it last ended, the backoff left...
  pid_t pid = 0;
  std::uint32_t restarts = 0;
};

class Supervisor {
 public:
  struct Hooks {
    /// A process (re)started; the fleet forgets what it saw of the node.
    std::function<void(const std::string& name, pid_t pid)> started;
    /// A process ended; `expected` when we stopped or killed it ourselves.
    std::function<void(const std::string& name, const std::string& how, bool expected)> ended;
  };

  /// How long a node may take to stop after SIGTERM before it gets SIGKILL.
  static constexpr std::chrono::milliseconds kStopGrace{5'000};

  Supervisor(asio::io_context& io, Scheduler& scheduler, Hooks hooks);
  ~Supervisor();

  void Add(const std::string& name, LaunchSpec launch, RestartPolicy policy);
  bool Has(const std::string& name) const { return nodes_.count(name) != 0; }

  /// Starts a node that is not running (idempotent). Returns false with `error` set when the
  /// process could not be started.
  bool Start(const std::string& name, std::string* error = nullptr);
  void StartAll();

  /// Kill fault: SIGKILL; the node stays down (no restart) until Start().
  void Kill(const std::string& name);
  /// Restart fault (`hard` = power-cycle: SIGKILL, else SIGTERM), then start again once reaped.
  void Restart(const std::string& name, bool hard);

  /// SIGTERM to every process, SIGKILL to those still alive after kStopGrace; `done` runs once
  /// every process has been reaped. No restarts after this.
  void StopAll(std::function<void()> done);

  ProcessView View(const std::string& name) const;

 private:
  enum class State : std::uint8_t { kIdle, kRunning, kBackoff, kExited, kKilled, kStopped };
  /// After the process ends: what to do.
  enum class Then : std::uint8_t { kPolicy, kStayDown, kStartAgain, kStop };
  struct Node {
    std::string name;
    LaunchSpec launch;
    RestartPolicy policy;
    State state = State::kIdle;
    Then then = Then::kPolicy;
    pid_t pid = 0;
    std::uint32_t restarts = 0;
    RestartBackoff restart_backoff{std::chrono::milliseconds(0)};
    TimePoint started_at{};  ///< scheduler time of the last start
    std::string detail;
    std::unique_ptr<Timer> backoff;
    std::unique_ptr<Timer> kill_after_grace;
  };

  void WaitForChildren();
  void Reap();
  void OnEnded(Node& node, int status);
  void Signal(Node& node, int signal);
  void CheckAllStopped();

  Scheduler& scheduler_;
  Hooks hooks_;
  asio::signal_set sigchld_;
  std::map<std::string, Node> nodes_;
  bool stopping_ = false;
  std::function<void()> all_stopped_;
  std::unique_ptr<Timer> give_up_;  ///< StopAll's deadline
};

}  // namespace canfleet::fleet
