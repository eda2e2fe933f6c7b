#pragma once
/// @file The socketcand endpoint on simulated time: a broker on a SimulatedScheduler and the server
/// on an io_context, both driven by the test's own thread (no background thread, no clock). Each
/// client is one end of a socketpair whose other end the server adopts (Server::Adopt): the kernel
/// moves a socketpair's bytes within the write call, so what a client reads depends on what the
/// test did and on simulated time only. Real TCP and real time: tests/integration/socketcand.

#include <fcntl.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <asio/executor_work_guard.hpp>
#include <asio/generic/stream_protocol.hpp>
#include <asio/io_context.hpp>
#include <cerrno>
#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "clock/scheduler.hpp"
#include "orchestrator/broker/broker.hpp"
#include "orchestrator/socketcand/server.hpp"

namespace canfleet::socketcand::test {

using namespace std::chrono_literals;

/// Records what a broker port receives.
class CollectingSink final : public broker::PortSink {
 public:
  void Deliver(std::span<const broker::TimedFrame> batch) override {
    for (const auto& f : batch)
      frames.push_back(f.frame);
  }
  void ControllerChanged(const ControllerEvent& event) override { states.push_back(event.state); }
  std::vector<CanFrame> frames;
  std::vector<ControllerState> states;
};

/// Broker + socketcand server serving one bus, plus a C++ port ("cpp") on that bus.
class Endpoint {
 public:
  explicit Endpoint(ServerOptions options = {},
                    broker::BusConfig bus = {.name = "can0", .bitrate = 1'000'000})
      : bus_(bus.name) {
    broker_.AddBus(bus);
    server_ = std::make_unique<Server>(io_, broker_, scheduler_, std::move(options));
    server_->Offer(bus.name);
    cpp_port_ = broker_.Attach(bus.name, "cpp", cpp_);
  }
  ~Endpoint() {
    server_->Stop();
    if (cpp_port_ != 0) broker_.Detach(cpp_port_);
    Settle();
  }

  /// Runs every handler that is ready (completed socket operations, posted work) until none is.
  /// Simulated time stands still meanwhile.
  void Settle() {
    while (io_.poll() > 0) {
    }
  }

  /// Settles, then moves simulated time forward from one timer's deadline to the next, settling
  /// after each, until `done` holds or `limit` of simulated time has passed. Returns done().
  bool RunUntil(const std::function<bool()>& done, Duration limit = 10s) {
    const TimePoint end = scheduler_.Now() + limit;
    for (;;) {
      Settle();
      if (done()) return true;
      const auto next = scheduler_.NextDeadline();
      if (!next || *next > end) return false;
      scheduler_.AdvanceTo(*next);
    }
  }

  /// Lets `d` of simulated time pass, with everything that falls due on the way.
  void RunFor(Duration d) {
    const TimePoint end = scheduler_.Now() + d;
    RunUntil([] { return false; }, d);
    scheduler_.AdvanceTo(end);
    Settle();
  }

  /// Hands the server one end of a new socketpair; returns the client's end.
  int Connect(int server_send_buffer = 0) {
    int fds[2];
    if (::socketpair(AF_UNIX, SOCK_STREAM, 0, fds) != 0) return -1;
    if (server_send_buffer > 0)
      ::setsockopt(fds[1], SOL_SOCKET, SO_SNDBUF, &server_send_buffer, sizeof server_send_buffer);
    ::fcntl(fds[0], F_SETFL, ::fcntl(fds[0], F_GETFL) | O_NONBLOCK);
    asio::generic::stream_protocol::socket socket(io_);
    socket.assign(asio::generic::stream_protocol(AF_UNIX, SOCK_STREAM), fds[1]);
    server_->Adopt(std::move(socket), bus_, "client-" + std::to_string(++clients_));
    Settle();
    return fds[0];
  }

  /// Frames from the C++ side's port.
  void Send(const std::vector<CanFrame>& frames) { broker_.Submit(cpp_port_, frames); }
  /// What the C++ side's port received so far.
  const std::vector<CanFrame>& Received() const { return cpp_.frames; }
  /// Runs until the C++ side has received `count` frames (or `limit` of simulated time).
  std::vector<CanFrame> WaitReceived(std::size_t count, Duration limit = 5s) {
    RunUntil([&] { return cpp_.frames.size() >= count; }, limit);
    return cpp_.frames;
  }
  /// Takes the C++ side's port off the bus (a client is then alone on it).
  void DetachCpp() { broker_.Detach(std::exchange(cpp_port_, 0)); }
  ServerStats Stats() const { return server_->Stats(); }
  std::size_t PortsOnBus() const { return broker_.Ports(bus_).size(); }
  TimePoint Now() const { return scheduler_.Now(); }
  Server& server() { return *server_; }

 private:
  std::string bus_;
  SimulatedScheduler scheduler_;
  broker::Broker broker_{scheduler_};
  // After the scheduler and the broker: handlers destroyed with the io_context may still hold
  // sessions, whose timers and ports belong to those two.
  asio::io_context io_;
  asio::executor_work_guard<asio::io_context::executor_type> work_ = asio::make_work_guard(io_);
  std::unique_ptr<Server> server_;
  CollectingSink cpp_;
  broker::PortId cpp_port_ = 0;
  int clients_ = 0;
};

/// A socketcand client on its end of a socketpair. Every wait runs the endpoint on simulated time
/// (Endpoint::RunUntil) for at most `limit`.
class Client {
 public:
  explicit Client(Endpoint& endpoint, int server_send_buffer = 0)
      : ep_(endpoint), fd_(endpoint.Connect(server_send_buffer)) {}
  ~Client() { Close(); }
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;

  bool connected() const { return fd_ >= 0; }

  /// Closes the client's end, as a script that exits does.
  void Close() {
    if (fd_ >= 0) ::close(std::exchange(fd_, -1));
  }

  /// Writes all of `text`; while the server does not read (a full socket buffer), runs the
  /// endpoint until it does.
  void Send(std::string_view text) {
    std::size_t done = 0;
    while (done < text.size()) {
      const ssize_t n = ::send(fd_, text.data() + done, text.size() - done, MSG_NOSIGNAL);
      if (n > 0) {
        done += static_cast<std::size_t>(n);
        continue;
      }
      if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK) return;
      if (!ep_.RunUntil([&] { return Ready(POLLOUT); })) return;
    }
    ep_.Settle();
  }

  /// One recv() of up to `max` bytes, as python-can reads; nullopt when nothing arrives within
  /// `limit`, "" on EOF.
  std::optional<std::string> RecvOnce(std::size_t max = 1024, Duration limit = 3s) {
    if (!ep_.RunUntil([&] { return Ready(POLLIN); }, limit)) return std::nullopt;
    std::string buf(max, '\0');
    const ssize_t n = ::recv(fd_, buf.data(), max, 0);
    if (n <= 0) return std::string();
    buf.resize(static_cast<std::size_t>(n));
    return buf;
  }

  /// The next element "< ... >" (padding skipped); nullopt when none completes within `limit` or
  /// the server closed the connection.
  std::optional<std::string> Next(Duration limit = 3s) {
    bool eof = false;
    std::optional<std::string> element;
    ep_.RunUntil(
        [&] {
          eof = eof || !Drain();
          element = Take();
          return element.has_value() || eof;
        },
        limit);
    return element;
  }

  /// True when the server closed the connection within `limit` (data before EOF is skipped).
  bool ClosedByServer(Duration limit = 3s) {
    return ep_.RunUntil([&] { return !Drain(); }, limit);
  }

  /// Opens `bus` and enters raw mode, checking each reply exactly as python-can does.
  bool Handshake(const std::string& bus = "can0") {
    if (RecvOnce(256) != "< hi >") return false;
    Send("< open " + bus + " >");
    if (RecvOnce(256) != "< ok >") return false;
    Send("< rawmode >");
    return RecvOnce(256) == "< ok >";
  }

 private:
  bool Ready(short events) const {
    pollfd p{fd_, events, 0};
    return ::poll(&p, 1, 0) > 0;
  }
  /// Reads what is there into buffer_; false on EOF (or a closed descriptor).
  bool Drain() {
    char chunk[4096];
    for (;;) {
      const ssize_t n = ::recv(fd_, chunk, sizeof chunk, 0);
      if (n > 0) {
        buffer_.append(chunk, static_cast<std::size_t>(n));
        continue;
      }
      return n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK);
    }
  }
  std::optional<std::string> Take() {
    const auto open = buffer_.find('<');
    const auto close = open == std::string::npos ? std::string::npos : buffer_.find('>', open);
    if (close == std::string::npos) return std::nullopt;
    std::string element = buffer_.substr(open, close + 1 - open);
    buffer_.erase(0, close + 1);
    return element;
  }

  Endpoint& ep_;
  int fd_ = -1;
  std::string buffer_;
};

}  // namespace canfleet::socketcand::test
