#include "orchestrator/fleet/supervisor.hpp"

#include <spdlog/spdlog.h>
#include <sys/wait.h>

#include <csignal>

namespace canfleet::fleet {

Supervisor::Supervisor(asio::io_context& io, Scheduler& scheduler, Hooks hooks)
    : scheduler_(scheduler), hooks_(std::move(hooks)), sigchld_(io, SIGCHLD) {
  WaitForChildren();
}

Supervisor::~Supervisor() {
  // Last resort (the normal path is StopAll): never leave a node running.
  for (auto& [name, node] : nodes_)
    if (node.pid > 0) ::kill(node.pid, SIGKILL);
}

void Supervisor::Add(const std::string& name, LaunchSpec launch, RestartPolicy policy) {
  Node node;
  node.name = name;
  node.launch = std::move(launch);
  node.policy = policy;
  node.restart_backoff = RestartBackoff(policy.backoff);
  nodes_.emplace(name, std::move(node));
}

bool Supervisor::Start(const std::string& name, std::string* error) {
  auto it = nodes_.find(name);
  if (it == nodes_.end() || stopping_) return false;
  Node& node = it->second;
  if (node.state == State::kRunning) return true;
  if (node.backoff) node.backoff->Cancel();
  try {
    node.pid = SpawnChild(node.launch);
  } catch (const std::exception& e) {
    node.state = State::kExited;
    node.detail = std::string("could not start: ") + e.what();
    spdlog::error("{}: {}", name, node.detail);
    if (error) *error = node.detail;
    return false;
  }
  node.state = State::kRunning;
  node.started_at = scheduler_.Now();
  node.then = Then::kPolicy;
  node.detail.clear();
  spdlog::info("{}: started, pid {} (log {})", name, node.pid, node.launch.log_file.string());
  spdlog::debug("{}: {}", name, CommandLine(node.launch));
  if (hooks_.started) hooks_.started(name, node.pid);
  return true;
}

void Supervisor::StartAll() {
  for (auto& [name, node] : nodes_)
    Start(name);
}

void Supervisor::Kill(const std::string& name) {
  auto it = nodes_.find(name);
  if (it == nodes_.end()) return;
  Node& node = it->second;
  if (node.backoff) node.backoff->Cancel();
  if (node.state == State::kRunning) {
    node.then = Then::kStayDown;
    Signal(node, SIGKILL);
  } else {
    node.state = State::kKilled;
    node.detail = "killed by a fault";
  }
}

void Supervisor::Restart(const std::string& name, bool hard) {
  auto it = nodes_.find(name);
  if (it == nodes_.end()) return;
  Node& node = it->second;
  if (node.state != State::kRunning) {
    Start(name);
    return;
  }
  node.then = Then::kStartAgain;
  Signal(node, hard ? SIGKILL : SIGTERM);
  if (!hard) {
    if (!node.kill_after_grace)
      node.kill_after_grace = std::make_unique<Timer>(scheduler_, [this, &node] { Signal(node, SIGKILL); });
    node.kill_after_grace->StartAfter(kStopGrace);
  }
}

void Supervisor::StopAll(std::function<void()> done) {
  stopping_ = true;
  all_stopped_ = std::move(done);
  // Whatever happens to the processes, the orchestrator ends: SIGKILL goes out after the grace
  // time, and one second later we stop waiting for the reaper.
  if (!give_up_) {
    give_up_ = std::make_unique<Timer>(scheduler_, [this] {
      for (auto& [name, node] : nodes_)
        if (node.state == State::kRunning) {
          spdlog::error("{}: not reaped after SIGKILL; giving up on it", name);
          node.state = State::kStopped;
        }
      CheckAllStopped();
    });
  }
  give_up_->StartAfter(kStopGrace + std::chrono::seconds(1));
  for (auto& entry : nodes_) {
    Node& node = entry.second;  // a reference the timer below can capture (not a structured binding)
    if (node.backoff) node.backoff->Cancel();
    if (node.state != State::kRunning) continue;
    if (node.pid <= 0) {
      node.state = State::kStopped;
      continue;
    }
    node.then = Then::kStop;
    Signal(node, SIGTERM);
    if (!node.kill_after_grace)
      node.kill_after_grace = std::make_unique<Timer>(scheduler_, [this, &node] {
        if (node.pid > 0)
          spdlog::warn("{}: still running {} ms after SIGTERM, sending SIGKILL", node.name,
                       kStopGrace.count());
        Signal(node, SIGKILL);
      });
    node.kill_after_grace->StartAfter(kStopGrace);
  }
  CheckAllStopped();
}

ProcessView Supervisor::View(const std::string& name) const {
  ProcessView view;
  auto it = nodes_.find(name);
  if (it == nodes_.end()) return view;
  const Node& node = it->second;
  switch (node.state) {
    case State::kIdle:
      view.state = "not started";
      break;
    case State::kRunning:
      view.state = "running";
      break;
    case State::kBackoff:
      view.state = "restarting";
      break;
    case State::kExited:
      view.state = "exited";
      break;
    case State::kKilled:
      view.state = "killed";
      break;
    case State::kStopped:
      view.state = "stopped";
      break;
  }
  view.detail = node.detail;
  view.pid = node.state == State::kRunning ? node.pid : 0;
  view.restarts = node.restarts;
  return view;
}

void Supervisor::Signal(Node& node, int signal) {
  if (node.pid > 0) ::kill(node.pid, signal);
}

void Supervisor::WaitForChildren() {
  sigchld_.async_wait([this](const asio::error_code& ec, int) {
    if (ec) return;
    Reap();
    WaitForChildren();
  });
}

void Supervisor::Reap() {
  // One SIGCHLD may stand for several children.
  for (;;) {
    int status = 0;
    const pid_t pid = ::waitpid(-1, &status, WNOHANG);
    if (pid <= 0) return;
    for (auto& [name, node] : nodes_) {
      if (node.pid == pid) {
        OnEnded(node, status);
        break;
      }
    }
  }
}

void Supervisor::OnEnded(Node& node, int status) {
  node.pid = 0;
  node.state = State::kExited;  // until decided below (Start() needs it not running)
  if (node.kill_after_grace) node.kill_after_grace->Cancel();
  const std::string how = DescribeWaitStatus(status);
  const bool failed = !(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  const Then then = stopping_ ? Then::kStop : node.then;
  node.then = Then::kPolicy;
  const bool expected = then != Then::kPolicy;
  if (hooks_.ended) hooks_.ended(node.name, how, expected);

  switch (then) {
    case Then::kStop:
      node.state = State::kStopped;
      node.detail = how;
      spdlog::info("{}: stopped ({})", node.name, how);
      CheckAllStopped();
      return;
    case Then::kStayDown:
      node.state = State::kKilled;
      node.detail = "killed by a fault (" + how + ")";
      spdlog::warn("{}: killed by a fault; stays down until the fault is cleared", node.name);
      return;
    case Then::kStartAgain:
      spdlog::info("{}: ended ({}), starting again", node.name, how);
      Start(node.name);
      return;
    case Then::kPolicy:
      break;
  }
  node.detail = how;
  const bool may_restart = node.policy.on_failure && failed &&
                           (node.policy.max_restarts == 0 || node.restarts < node.policy.max_restarts);
  if (!may_restart) {
    node.state = State::kExited;
    spdlog::error("{}: process ended ({}){}", node.name, how,
                  failed && node.policy.on_failure ? "; restart limit reached" : "");
    return;
  }
  node.state = State::kBackoff;
  const auto delay = node.restart_backoff.After(scheduler_.Now() - node.started_at);
  ++node.restarts;
  node.detail =
      how + ", restart " + std::to_string(node.restarts) + " in " + std::to_string(delay.count()) + " ms";
  spdlog::error("{}: process ended ({}); restarting in {} ms (restart {})", node.name, how, delay.count(),
                node.restarts);
  if (!node.backoff) node.backoff = std::make_unique<Timer>(scheduler_, [this, &node] { Start(node.name); });
  node.backoff->StartAfter(delay);
}

void Supervisor::CheckAllStopped() {
  if (!stopping_ || !all_stopped_) return;
  for (const auto& [name, node] : nodes_)
    if (node.state == State::kRunning) return;
  if (give_up_) give_up_->Cancel();
  auto done = std::move(all_stopped_);
  all_stopped_ = nullptr;
  done();
}

}  // namespace canfleet::fleet
