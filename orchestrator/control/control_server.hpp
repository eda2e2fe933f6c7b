#pragma once
/// @file The control API's server side: accepts TCP connections, decodes Requests and hands each
/// to a ControlHandler with a Responder for its connection (canfleet_control.proto).

#include <asio/io_context.hpp>
#include <asio/ip/tcp.hpp>
#include <chrono>
#include <cstddef>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "bus/wire/auth_gate.hpp"
#include "orchestrator/control/control_handler.hpp"
#include "orchestrator/control/control_protocol.hpp"

namespace canfleet::control {

namespace detail {
class ControlSession;
}

struct ControlServerOptions {
  /// Largest Request accepted and Response sent (without the length prefix).
  std::size_t max_message = kMaxControlMessage;
  /// Bytes of responses a connection may have waiting for a client that does not read. Beyond
  /// it, FrameBatch responses (dumps) are dropped and counted; other responses are still queued.
  std::size_t max_backlog_bytes = std::size_t{16} << 20;
  /// A connection whose backlog has stayed full this long (batches dropped all along) is closed
  /// with the reason logged (transport/slow_reader.hpp).
  std::chrono::milliseconds slow_reader_limit{30'000};
  /// A message begun (its length prefix or part of its body read) must be complete this long
  /// after; else the connection is closed as a protocol error.
  std::chrono::milliseconds message_timeout{30'000};
  /// When a connection is closed by the server (protocol error, Close), how long what is queued
  /// (an error response, a Shutdown's Done) may take to leave before the socket is closed anyway.
  std::chrono::milliseconds close_linger{1'000};
  /// The fleet's token (bus/wire/auth_token.hpp). Listening beyond loopback needs one; clients
  /// there must send it (wire/auth_gate.hpp). Empty: loopback only.
  std::string token{};
  /// From accept until the client's first bytes (its token, or its first request on loopback).
  std::chrono::milliseconds handshake_timeout{10'000};
  /// Connections waiting at the gate at once; one more is closed at once.
  std::size_t max_pending = 64;
  /// Sessions at once; one more is refused with an error Response saying so.
  std::size_t max_sessions = 64;
};

struct ControlServerStats {
  std::uint64_t accepted = 0;         ///< connections accepted
  std::uint64_t requests = 0;         ///< requests handed to the handler
  std::uint64_t protocol_errors = 0;  ///< connections closed for malformed or oversized messages
  std::uint64_t dropped_batches = 0;  ///< FrameBatch responses not queued for slow readers
  std::uint64_t refused = 0;          ///< connections refused: no or wrong token, too many
  std::uint64_t slow_readers = 0;     ///< connections closed for not reading (slow_reader_limit)
};

/// Accepts connections and runs one session per connection, as asio's chat_server does: each
/// session reads varint-length-delimited Requests (at most ControlServerOptions::max_message
/// bytes) and calls ControlHandler::Handle for each, on the io thread, with the connection's
/// Responder; responses are queued and written one write at a time. A malformed or oversized
/// message gets an error Response (id 0) and closes that connection, with the reason logged; the
/// other connections carry on. A Request without a body is answered with an error without
/// reaching the handler; an exception thrown by the handler becomes an error Response.
///
/// Threading: everything runs on the thread running `io`; the handler is called there and must
/// use its Responders there.
class ControlServer {
 public:
  /// `handler` must outlive the server.
  ControlServer(asio::io_context& io, ControlHandler& handler, ControlServerOptions options = {});
  /// Closes the listeners and every connection.
  ~ControlServer();
  ControlServer(const ControlServer&) = delete;
  ControlServer& operator=(const ControlServer&) = delete;

  /// Starts accepting on `endpoint`, `tcp://HOST:PORT` (port 0: any free port) and returns where
  /// it listens. Loopback unless another address is given explicitly; beyond loopback every
  /// client must send the token (ControlServerOptions::token). May be called more than once
  /// (several addresses). Throws std::invalid_argument for a malformed endpoint,
  /// std::runtime_error for an address beyond loopback without a token, and std::system_error
  /// when it cannot be resolved or bound.
  asio::ip::tcp::endpoint Listen(const std::string& endpoint);

  /// Stops accepting and closes every connection (OnClose handlers run now; what is already
  /// queued may still leave within close_linger while `io` runs). Idempotent.
  void Close();

  std::size_t SessionCount() const { return sessions_.size(); }
  const std::vector<asio::ip::tcp::endpoint>& Endpoints() const { return endpoints_; }
  const ControlServerStats& Stats() const { return *stats_; }
  const wire::AuthGateStats& GateStats() const { return *gate_stats_; }

 private:
  void Accept(std::size_t index);
  void Admit(asio::ip::tcp::socket socket, const std::string& peer);
  void Remove(detail::ControlSession* session);

  asio::io_context& io_;
  ControlHandler& handler_;
  ControlServerOptions options_;
  std::shared_ptr<ControlServerStats> stats_ = std::make_shared<ControlServerStats>();
  /// Owned by the server alone: acceptor handlers that outlive it see it expired.
  std::shared_ptr<int> alive_ = std::make_shared<int>(0);
  std::vector<std::unique_ptr<asio::ip::tcp::acceptor>> acceptors_;
  std::vector<asio::ip::tcp::endpoint> endpoints_;
  std::vector<wire::AuthPolicy> policies_;  ///< one per acceptor
  std::shared_ptr<wire::AuthGateStats> gate_stats_ = std::make_shared<wire::AuthGateStats>();
  std::unordered_map<detail::ControlSession*, std::shared_ptr<detail::ControlSession>> sessions_;
  std::uint64_t next_session_ = 1;
  bool closed_ = false;
  bool gate_full_logged_ = false;
};

}  // namespace canfleet::control
