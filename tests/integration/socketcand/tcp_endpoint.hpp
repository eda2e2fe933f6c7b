#pragma once
/// @file Helpers for the socketcand endpoint's integration tests: a broker and a server on an Asio
/// event loop in a background thread (real time, real TCP on loopback), and a blocking test
/// client with timeouts.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <asio/executor_work_guard.hpp>
#include <asio/io_context.hpp>
#include <asio/post.hpp>
#include <chrono>
#include <functional>
#include <future>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "clock/asio_scheduler.hpp"
#include "orchestrator/broker/broker.hpp"
#include "orchestrator/socketcand/server.hpp"

namespace canfleet::socketcand::test {

using namespace std::chrono_literals;

/// Records what a broker port receives; read it from the test thread through Endpoint::OnIo.
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

/// Broker + socketcand server on an io_context run by a background thread. Every access to the
/// broker, the server or a sink goes through OnIo (the broker is single-threaded).
class Endpoint {
 public:
  explicit Endpoint(ServerOptions options = {},
                    broker::BusConfig bus = {.name = "can0", .bitrate = 1'000'000}) {
    broker_.AddBus(bus);
    server_ = std::make_unique<Server>(io_, broker_, scheduler_, std::move(options));
    port_ = server_->Serve(bus.name, 0);
    cpp_port_ = broker_.Attach(bus.name, "cpp", cpp_);
    thread_ = std::thread([this] { io_.run(); });
  }
  ~Endpoint() {
    OnIo([this] {
      server_->Stop();
      if (cpp_port_ != 0) broker_.Detach(cpp_port_);
    });
    work_.reset();
    io_.stop();
    thread_.join();
  }

  /// Runs `f` on the event loop and returns its result.
  template <typename F>
  auto OnIo(F f) -> decltype(f()) {
    std::packaged_task<decltype(f())()> task(std::move(f));
    auto result = task.get_future();
    asio::post(io_, [&task] { task(); });
    return result.get();
  }

  /// Frames from the C++ side's port.
  void Send(const std::vector<CanFrame>& frames) {
    OnIo([&] { return broker_.Submit(cpp_port_, frames); });
  }
  /// What the C++ side's port received so far.
  std::vector<CanFrame> Received() {
    return OnIo([this] { return cpp_.frames; });
  }
  /// Waits until the C++ side has received `count` frames (or `timeout`).
  std::vector<CanFrame> WaitReceived(std::size_t count, std::chrono::milliseconds timeout = 10s) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      auto frames = Received();
      if (frames.size() >= count || std::chrono::steady_clock::now() > end) return frames;
      std::this_thread::sleep_for(2ms);
    }
  }
  /// Takes the C++ side's port off the bus (a client is then alone on it).
  void DetachCpp() {
    OnIo([this] { return broker_.Detach(std::exchange(cpp_port_, 0)); });
  }
  ServerStats Stats() {
    return OnIo([this] { return server_->Stats(); });
  }
  std::size_t PortsOnBus() {
    return OnIo([this] { return broker_.Ports("can0").size(); });
  }

  std::uint16_t port() const { return port_; }
  broker::Broker& broker() { return broker_; }
  Server& server() { return *server_; }

 private:
  asio::io_context io_;
  asio::executor_work_guard<asio::io_context::executor_type> work_ = asio::make_work_guard(io_);
  AsioScheduler scheduler_{io_};
  broker::Broker broker_{scheduler_};
  std::unique_ptr<Server> server_;
  CollectingSink cpp_;
  broker::PortId cpp_port_ = 0;
  std::uint16_t port_ = 0;
  std::thread thread_;
};

/// A blocking socketcand client (plain POSIX sockets) whose reads time out.
class Client {
 public:
  explicit Client(std::uint16_t port, int receive_buffer = 0) {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    if (receive_buffer > 0) ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &receive_buffer, sizeof receive_buffer);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(port);
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    connected_ = ::connect(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0;
  }
  ~Client() { ::close(fd_); }
  bool connected() const { return connected_; }

  void Send(std::string_view text) {
    std::size_t done = 0;
    while (done < text.size()) {
      const ssize_t n = ::send(fd_, text.data() + done, text.size() - done, MSG_NOSIGNAL);
      if (n <= 0) return;
      done += static_cast<std::size_t>(n);
    }
  }

  /// One recv() of up to `max` bytes, as python-can reads; nullopt on timeout, "" on EOF.
  std::optional<std::string> RecvOnce(std::size_t max = 1024, std::chrono::milliseconds timeout = 10s) {
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(timeout.count())) <= 0) return std::nullopt;
    std::string buf(max, '\0');
    const ssize_t n = ::recv(fd_, buf.data(), max, 0);
    if (n <= 0) return std::string();
    buf.resize(static_cast<std::size_t>(n));
    return buf;
  }

  /// The next element "< ... >" (padding skipped); nullopt on timeout or EOF.
  std::optional<std::string> Next(std::chrono::milliseconds timeout = 10s) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      const auto open = buffer_.find('<');
      const auto close = open == std::string::npos ? std::string::npos : buffer_.find('>', open);
      if (close != std::string::npos) {
        std::string element = buffer_.substr(open, close + 1 - open);
        buffer_.erase(0, close + 1);
        return element;
      }
      const auto left =
          std::chrono::duration_cast<std::chrono::milliseconds>(end - std::chrono::steady_clock::now());
      if (left <= 0ms) return std::nullopt;
      const auto chunk = RecvOnce(4096, left);
      if (!chunk || chunk->empty()) return std::nullopt;
      buffer_ += *chunk;
    }
  }

  /// True when the server closed the connection within `timeout` (data before EOF is skipped).
  bool ClosedByServer(std::chrono::milliseconds timeout = 10s) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < end) {
      const auto chunk = RecvOnce(4096, 100ms);
      if (chunk && chunk->empty()) return true;
    }
    return false;
  }

  /// Connects, opens `bus` and enters raw mode, checking each reply exactly as python-can does.
  bool Handshake(const std::string& bus = "can0") {
    if (RecvOnce(256) != "< hi >") return false;
    Send("< open " + bus + " >");
    if (RecvOnce(256) != "< ok >") return false;
    Send("< rawmode >");
    return RecvOnce(256) == "< ok >";
  }

 private:
  int fd_ = -1;
  bool connected_ = false;
  std::string buffer_;
};

}  // namespace canfleet::socketcand::test
