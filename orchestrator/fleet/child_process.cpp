#include "orchestrator/fleet/child_process.hpp"

#include <fcntl.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <system_error>

namespace canfleet::fleet {

namespace {

/// The highest descriptor closed one by one where close_range is missing (the default soft limit
/// of open files is 1024; the orchestrator raises none).
constexpr int kMaxInheritedFd = 65536;

}  // namespace

pid_t SpawnChild(const LaunchSpec& spec) {
  // Everything the child needs is prepared before fork: between fork and exec only
  // async-signal-safe calls are allowed (the orchestrator has DDS and Asio threads).
  const std::string binary = spec.binary.string();
  std::vector<std::string> strings;
  strings.reserve(spec.args.size() + 1);
  strings.push_back(binary);
  strings.insert(strings.end(), spec.args.begin(), spec.args.end());
  std::vector<char*> argv;
  for (auto& s : strings)
    argv.push_back(s.data());
  argv.push_back(nullptr);

  if (!spec.log_file.parent_path().empty()) std::filesystem::create_directories(spec.log_file.parent_path());
  const int log = ::open(spec.log_file.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (log < 0)
    throw std::system_error(errno, std::generic_category(), "cannot open " + spec.log_file.string());
  const pid_t parent = ::getpid();

  const pid_t pid = ::fork();
  if (pid < 0) {
    const int error = errno;
    ::close(log);
    throw std::system_error(error, std::generic_category(), "fork");
  }
  if (pid == 0) {
    // Child. SIGTERM when the orchestrator dies (whatever the reason); if it already died between
    // fork and prctl, leave now.
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (::getppid() != parent) ::_exit(127);
    // Its own process group: a Ctrl-C in the orchestrator's terminal reaches the orchestrator
    // only, which then stops the nodes in order.
    ::setpgid(0, 0);
    const int null = ::open("/dev/null", O_RDONLY);
    if (null >= 0) ::dup2(null, STDIN_FILENO);
    ::dup2(log, STDOUT_FILENO);
    ::dup2(log, STDERR_FILENO);
    // Nothing else of the orchestrator's goes along: Asio opens its sockets without close-on-exec,
    // and a node holding the control, broker or socketcand listeners (or other clients'
    // connections) would keep the fleet's ports bound after the orchestrator ended. close_range
    // where the kernel has it (5.9), else one close per possible descriptor.
    if (::close_range(3, ~0U, 0) != 0) {
      for (int fd = 3; fd < kMaxInheritedFd; ++fd)
        ::close(fd);
    }
    // The orchestrator's signal mask and dispositions are not the node's.
    sigset_t none;
    sigemptyset(&none);
    ::sigprocmask(SIG_SETMASK, &none, nullptr);
    ::signal(SIGPIPE, SIG_DFL);
    ::execv(argv[0], argv.data());
    const char message[] = "canfleet: exec of the node binary failed\n";
    (void)!::write(STDERR_FILENO, message, sizeof message - 1);
    ::_exit(127);
  }
  ::close(log);
  return pid;
}

std::string DescribeWaitStatus(int status) {
  if (WIFEXITED(status)) return "exit code " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) {
    const int sig = WTERMSIG(status);
    const char* name = ::strsignal(sig);
    return "signal " + std::to_string(sig) + (name ? std::string(" (") + name + ")" : std::string());
  }
  return "status " + std::to_string(status);
}

std::string CommandLine(const LaunchSpec& spec) {
  std::string line = spec.binary.string();
  for (const auto& arg : spec.args) {
    line += ' ';
    const bool quote = arg.find_first_of(" \t\"'") != std::string::npos || arg.empty();
    line += quote ? "'" + arg + "'" : arg;
  }
  return line;
}

}  // namespace canfleet::fleet
