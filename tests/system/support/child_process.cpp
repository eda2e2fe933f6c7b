#include "tests/system/support/child_process.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <signal.h>
#include <sys/ioctl.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "bus/wire/endpoint.hpp"

extern char** environ;

namespace canfleet::system_test {

namespace {

using Clock = std::chrono::steady_clock;

int RemainingMs(Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  return left < 0 ? 0 : static_cast<int>(left);
}

[[noreturn]] void Fail(const std::string& what) {
  throw std::runtime_error(what + ": " + std::strerror(errno));
}

}  // namespace

bool WaitUntil(const std::function<bool()>& condition, std::chrono::milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  for (;;) {
    if (condition()) return true;
    if (Clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

std::uint16_t FreeTcpPort() {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) Fail("socket");
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = 0;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) Fail("bind");
  socklen_t len = sizeof addr;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
  ::close(fd);
  return ntohs(addr.sin_port);
}

TempDir::TempDir() {
  char tmpl[] = "/tmp/cfst.XXXXXX";
  if (::mkdtemp(tmpl) == nullptr) Fail("mkdtemp");
  path_ = tmpl;
}

TempDir::~TempDir() {
  std::error_code ignored;
  std::filesystem::remove_all(path_, ignored);
}

ChildProcess::ChildProcess(std::vector<std::string> argv, std::string stderr_path)
    : stderr_path_(std::move(stderr_path)) {
  int in[2];
  int out[2];
  int exec_error[2];  // the child writes errno here if exec fails; closed by a successful exec
  if (::pipe2(in, O_CLOEXEC) != 0 || ::pipe2(out, O_CLOEXEC) != 0 || ::pipe2(exec_error, O_CLOEXEC) != 0)
    Fail("pipe2");
  const int err = ::open(stderr_path_.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (err < 0) Fail("open " + stderr_path_);
  std::vector<char*> args;
  for (auto& a : argv)
    args.push_back(a.data());
  args.push_back(nullptr);
  const pid_t parent = ::getpid();
  // fork + exec rather than posix_spawn, for PR_SET_PDEATHSIG: a test that crashes or is killed
  // (ctest's timeout) takes its children with it instead of leaving nodes and brokers running.
  // Between fork and exec only async-signal-safe calls (the test may run other threads).
  pid_ = ::fork();
  if (pid_ < 0) Fail("fork");
  if (pid_ == 0) {
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(127);  // the test died before prctl took effect
    ::dup2(in[0], STDIN_FILENO);
    ::dup2(out[1], STDOUT_FILENO);
    ::dup2(err, STDERR_FILENO);
    ::execve(args[0], args.data(), environ);
    const int error = errno;
    [[maybe_unused]] const auto ignored = ::write(exec_error[1], &error, sizeof error);
    ::_exit(127);
  }
  ::close(in[0]);
  ::close(out[1]);
  ::close(err);
  ::close(exec_error[1]);
  stdin_fd_ = in[1];
  stdout_fd_ = out[0];
  int error = 0;
  const ssize_t got = ::read(exec_error[0], &error, sizeof error);  // 0: exec succeeded
  ::close(exec_error[0]);
  if (got == sizeof error) {
    ::waitpid(pid_, nullptr, 0);
    pid_ = -1;
    errno = error;
    Fail("exec " + argv[0]);
  }
  ::fcntl(stdout_fd_, F_SETFL, ::fcntl(stdout_fd_, F_GETFL) | O_NONBLOCK);
  // A child that exits must not kill us with SIGPIPE when we write to its stdin.
  ::signal(SIGPIPE, SIG_IGN);
  reader_ = std::thread([this] { ReadStdout(); });
}

ChildProcess::~ChildProcess() {
  if (Running()) {
    ::kill(pid_, SIGKILL);
    Wait(std::chrono::seconds(30));
  }
  StopReader();
  if (stdin_fd_ >= 0) ::close(stdin_fd_);
  if (stdout_fd_ >= 0) ::close(stdout_fd_);
}

void ChildProcess::WriteLine(const std::string& line) {
  const std::string data = line + "\n";
  std::size_t done = 0;
  while (done < data.size()) {
    const ssize_t n = ::write(stdin_fd_, data.data() + done, data.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      return;  // the child is gone; the test sees it in its output
    }
    done += static_cast<std::size_t>(n);
  }
}

void ChildProcess::ReadStdout() {
  std::string partial;
  char buf[65536];
  for (;;) {
    {
      std::lock_guard lock(mutex_);
      if (stopping_) return;
    }
    // A bounded poll, so StopReader() is noticed even while the child (or a grandchild holding
    // the pipe) stays silent.
    pollfd p{stdout_fd_, POLLIN, 0};
    if (::poll(&p, 1, 50) <= 0) continue;
    {
      std::lock_guard lock(mutex_);
      in_flight_ = true;
    }
    const ssize_t n = ::read(stdout_fd_, buf, sizeof buf);
    std::lock_guard lock(mutex_);
    in_flight_ = false;
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) {
      new_lines_.notify_all();
      continue;
    }
    if (n <= 0) {
      stdout_closed_ = true;
      new_lines_.notify_all();
      return;
    }
    partial.append(buf, static_cast<std::size_t>(n));
    std::size_t start = 0;
    for (std::size_t nl; (nl = partial.find('\n', start)) != std::string::npos; start = nl + 1)
      lines_.push_back(partial.substr(start, nl - start));
    partial.erase(0, start);
    new_lines_.notify_all();
  }
}

void ChildProcess::StopReader() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  if (reader_.joinable()) reader_.join();
}

void ChildProcess::Poll() {
  // Bounded: a child writing without pause would otherwise keep the caller here.
  const auto deadline = Clock::now() + std::chrono::seconds(2);
  std::unique_lock lock(mutex_);
  for (;;) {
    int pending = 0;
    if (::ioctl(stdout_fd_, FIONREAD, &pending) != 0) pending = 0;
    if (stdout_closed_ || (!in_flight_ && pending == 0) || Clock::now() >= deadline) return;
    new_lines_.wait_for(lock, std::chrono::milliseconds(10));
  }
}

std::vector<std::string> ChildProcess::Lines() const {
  std::lock_guard lock(mutex_);
  return lines_;
}

std::optional<std::string> ChildProcess::WaitForLine(const std::function<bool(const std::string&)>& match,
                                                     std::chrono::milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  std::unique_lock lock(mutex_);
  for (;;) {
    for (; scanned_ < lines_.size(); ++scanned_)
      if (match(lines_[scanned_])) return lines_[scanned_++];
    if (stdout_closed_ || Clock::now() >= deadline) return std::nullopt;
    new_lines_.wait_until(lock, deadline);
  }
}

std::optional<std::string> ChildProcess::WaitForPrefix(const std::string& prefix,
                                                       std::chrono::milliseconds timeout) {
  return WaitForLine([&](const std::string& line) { return line.starts_with(prefix); }, timeout);
}

void ChildProcess::Signal(int signal) {
  if (Running()) ::kill(pid_, signal);
}

bool ChildProcess::Running() {
  if (status_) return false;
  int status = 0;
  const pid_t r = ::waitpid(pid_, &status, WNOHANG);
  if (r == pid_) {
    status_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return false;
  }
  return r == 0;
}

std::optional<int> ChildProcess::Wait(std::chrono::milliseconds timeout) {
  WaitUntil([&] { return !Running(); }, timeout);
  return status_;
}

std::string ChildProcess::Log() const {
  std::ifstream in(stderr_path_);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

RawConnection::RawConnection(const std::string& endpoint) {
  const wire::Endpoint ep = wire::Endpoint::Parse(endpoint);
  if (ep.kind == wire::Endpoint::Kind::kUnix) {
    fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    std::strncpy(addr.sun_path, ep.path.c_str(), sizeof(addr.sun_path) - 1);
    if (::connect(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
      ::close(fd_);
      fd_ = -1;
    }
    return;
  }
  fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(ep.port);
  ::inet_pton(AF_INET, ep.host == "localhost" ? "127.0.0.1" : ep.host.c_str(), &addr.sin_addr);
  if (::connect(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    ::close(fd_);
    fd_ = -1;
  }
}

RawConnection::~RawConnection() {
  if (fd_ >= 0) ::close(fd_);
}

bool RawConnection::Send(const std::string& bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::send(fd_, bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    done += static_cast<std::size_t>(n);
  }
  return true;
}

bool RawConnection::Send(const std::vector<std::uint8_t>& bytes) {
  return Send(std::string(bytes.begin(), bytes.end()));
}

RawConnection::ReadResult RawConnection::ReadAtLeast(std::size_t want, std::chrono::milliseconds timeout) {
  ReadResult result;
  const auto deadline = Clock::now() + timeout;
  while (result.bytes.size() < want) {
    pollfd p{fd_, POLLIN, 0};
    const int ready = ::poll(&p, 1, RemainingMs(deadline));
    if (ready <= 0) return result;
    std::uint8_t buf[65536];
    const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
    if (n <= 0) {
      if (n < 0 && errno == EINTR) continue;
      result.closed = true;  // orderly close, or reset by the peer
      return result;
    }
    result.bytes.insert(result.bytes.end(), buf, buf + n);
  }
  return result;
}

RawConnection::ReadResult RawConnection::ReadUntilClosed(std::chrono::milliseconds timeout) {
  return ReadAtLeast(SIZE_MAX, timeout);
}

}  // namespace canfleet::system_test
