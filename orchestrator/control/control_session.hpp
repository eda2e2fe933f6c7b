#pragma once
/// @file One client connection of the control API. Internal to ControlServer.

#include <spdlog/spdlog.h>

#include <array>
#include <asio/ip/tcp.hpp>
#include <asio/steady_timer.hpp>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "orchestrator/control/control_server.hpp"
#include "orchestrator/transport/slow_reader.hpp"

namespace canfleet::control::detail {

/// A session follows asio's chat_server (style.md, "Asio lifetimes"): it is owned by shared_ptrs,
/// every handler captures [this, self], and at most one write is in flight. Responses accumulate
/// in one buffer while a write is in flight and leave together in the next write.
///
/// The handler gets a Responder that refers to the session weakly, so a handler keeping a
/// Responder (a dump, a slow SDO transfer) does not keep a closed connection alive.
class ControlSession final : public std::enable_shared_from_this<ControlSession> {
 public:
  using ClosedHandler = std::function<void(ControlSession*)>;

  ControlSession(asio::ip::tcp::socket socket, ControlHandler& handler, const ControlServerOptions& options,
                 std::shared_ptr<ControlServerStats> stats, std::string label, ClosedHandler on_closed);

  void Start();

  /// Queues a response (ignored once closed).
  void Send(const Response& response);
  bool Closed() const { return closed_; }
  /// Runs `handler` when the session closes, or now if it has.
  void OnClose(std::function<void()> handler);

  /// Ends the session once: runs the OnClose handlers, then closes the socket, after writing what
  /// is queued (within close_linger) when `drain`.
  void Close(const std::string& reason, bool drain, spdlog::level::level_enum level);

 private:
  void Read();
  void WatchIncomplete();
  void Dispatch(const Request& request);
  void ProtocolError(const std::string& reason);
  void Flush();
  void CloseSocket();

  asio::ip::tcp::socket socket_;
  ControlHandler& handler_;
  const ControlServerOptions options_;
  std::shared_ptr<ControlServerStats> stats_;
  asio::steady_timer linger_;
  asio::steady_timer incomplete_;  ///< a message begun and not finished (message_timeout)
  bool incomplete_since_armed_ = false;
  std::string label_;  ///< "control session 3 (127.0.0.1:40312)"
  ClosedHandler on_closed_;
  std::shared_ptr<Responder> responder_;
  std::vector<std::function<void()>> close_handlers_;
  bool closed_ = false;

  std::array<std::uint8_t, 64 * 1024> read_buffer_;
  DelimitedReader reader_;
  Request request_;

  std::string filling_;  ///< responses queued while a write is in flight
  std::string writing_;  ///< the write in flight
  bool write_in_flight_ = false;
  /// FrameBatch responses dropped for a full backlog; closed after slow_reader_limit.
  transport::SlowReader slow_;
  bool slow_close_posted_ = false;
};

}  // namespace canfleet::control::detail
