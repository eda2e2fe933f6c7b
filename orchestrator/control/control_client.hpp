#pragma once
/// @file The control API's client side, blocking, for the `canfleet` CLI, scripts and tests.

#include <asio/io_context.hpp>
#include <asio/ip/tcp.hpp>
#include <chrono>
#include <cstdint>
#include <deque>
#include <optional>
#include <stdexcept>
#include <string>

#include "orchestrator/control/canfleet_control.pb.h"
#include "orchestrator/control/control_protocol.hpp"

namespace canfleet::control {

/// The orchestrator could not be reached, did not answer in time, broke the protocol or closed
/// the connection. what() is one line for the user: "no orchestrator at tcp://127.0.0.1:29700
/// (is `canfleet up` running?)". An error the orchestrator answered (Response.error) is not
/// thrown: it comes back in the Response.
class ControlError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One connection to the orchestrator's control API. Not thread-safe; one user at a time.
///
///     ControlClient client("tcp://127.0.0.1:29700");
///     Request request;
///     request.mutable_status();
///     const Response response = client.Call(request);
class ControlClient {
 public:
  static constexpr std::chrono::milliseconds kDefaultConnectTimeout{5'000};
  static constexpr std::chrono::milliseconds kDefaultCallTimeout{30'000};

  /// Connects to `endpoint` (`tcp://HOST:PORT`). Throws std::invalid_argument for a malformed
  /// endpoint and ControlError when nothing accepts the connection within `connect_timeout`.
  explicit ControlClient(const std::string& endpoint,
                         std::chrono::milliseconds connect_timeout = kDefaultConnectTimeout);
  ~ControlClient();
  ControlClient(const ControlClient&) = delete;
  ControlClient& operator=(const ControlClient&) = delete;

  /// Sends `request` (given the next id when its id is 0) and waits for the response with its id.
  /// Responses to other requests that arrive meanwhile are kept for Receive(). Throws ControlError
  /// on timeout, when the connection closes, and when the server reports a protocol error.
  Response Call(Request request, std::chrono::milliseconds timeout = kDefaultCallTimeout);

  /// Sends `request` without waiting (given the next id when its id is 0); returns its id. For
  /// streams (DumpRequest): read the responses with Receive(). Throws ControlError when the
  /// connection is lost.
  std::uint64_t Send(Request request);

  /// The next response, whatever its id. nullopt when none came within `timeout`, or early when a
  /// signal interrupted the wait (so a caller can check its SIGINT flag). Throws ControlError when
  /// the connection closes or the stream is malformed.
  std::optional<Response> Receive(std::chrono::milliseconds timeout);

  /// Closes the connection (a dump stream on the server stops). Idempotent.
  void Close();
  bool connected() const { return socket_.is_open(); }

  /// The endpoint as given ("tcp://127.0.0.1:29700").
  const std::string& endpoint() const { return endpoint_; }

 private:
  /// Sends the fleet's token (wire/auth_token.hpp) when one is set in the environment.
  void SendToken();
  /// Throws the orchestrator's refusal if one is waiting to be read.
  void ThrowRefusalIfAny();
  /// Reads what arrives within `timeout` into reader_; false on timeout or signal.
  bool ReadSome(std::chrono::milliseconds timeout);
  std::optional<Response> NextBuffered();

  std::string endpoint_;
  asio::io_context io_;
  asio::ip::tcp::socket socket_;
  DelimitedReader reader_;
  std::deque<Response> pending_;  ///< responses received while Call waited for another id
  std::uint64_t next_id_ = 1;
};

}  // namespace canfleet::control
