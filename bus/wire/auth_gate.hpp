#pragma once
/// @file The server's side of the auth preamble (auth_token.hpp): what every accepted TCP
/// connection of the control API and the broker passes before its session exists.
///
/// The gate looks at the connection's first bytes with MSG_PEEK, so a client without a preamble
/// reaches its session with nothing consumed. It holds the socket, a timer and a buffer of
/// kMaxAuthPreamble bytes: a client that never proves itself costs no session, no read buffer and
/// no queue, and the number of gates open at once is bounded by the server (AuthGateLimits).
///
/// - A listener on loopback (the default) needs no token: a client without a preamble is let in,
///   one with a preamble is checked when the server has a token (so a wrong token is refused
///   everywhere, a useful early hint) and let in when it has none.
/// - A listener beyond loopback needs one: no preamble, a malformed one, a wrong token, or
///   nothing within the handshake timeout, and the connection is refused (on loopback a client
///   silent that long is let in: it may speak later): the protocol's own
///   refusal (an error Response, a refused HelloReply) names the reason, and the server logs it
///   with the peer's address.

#include <sys/socket.h>

#include <array>
#include <asio/socket_base.hpp>
#include <asio/steady_timer.hpp>
#include <cerrno>
#include <chrono>
#include <functional>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>

#include "bus/wire/auth_token.hpp"

namespace canfleet::wire {

struct AuthPolicy {
  /// The listener reaches beyond loopback: a client must send the token.
  bool required = false;
  /// The fleet's token; empty when none is configured (then `required` cannot be set: servers
  /// refuse to listen beyond loopback without one).
  std::string token;
  /// From accept until the first bytes decide (a preamble, or a client's own first message).
  std::chrono::milliseconds handshake_timeout{10'000};
};

struct AuthGateStats {
  std::uint64_t admitted = 0;
  std::uint64_t refused = 0;    ///< no token, malformed, wrong token
  std::uint64_t timed_out = 0;  ///< nothing decided within the handshake timeout
  std::uint64_t pending = 0;    ///< gates open now
};

/// What the owner of a gate does with its outcome.
template <class Socket>
struct AuthGateHandlers {
  /// Gets the socket of a client let in, its preamble (if any) consumed.
  std::function<void(Socket)> admit;
  /// The bytes that tell a refused client why, in its protocol (written once, best effort).
  std::function<std::string(const std::string& reason)> refusal;
  /// Logs a refusal (the gate itself does not know the server's log vocabulary).
  std::function<void(const std::string& reason)> log_refusal;
};

template <class Socket>
class AuthGate final : public std::enable_shared_from_this<AuthGate<Socket>> {
 public:
  static void Run(Socket socket, const AuthPolicy& policy, AuthGateHandlers<Socket> handlers,
                  std::shared_ptr<AuthGateStats> stats) {
    auto gate = std::shared_ptr<AuthGate>(
        new AuthGate(std::move(socket), policy, std::move(handlers), std::move(stats)));
    gate->Start();
  }

  ~AuthGate() { --stats_->pending; }

 private:
  AuthGate(Socket socket, const AuthPolicy& policy, AuthGateHandlers<Socket> handlers,
           std::shared_ptr<AuthGateStats> stats)
      : socket_(std::move(socket)),
        policy_(policy),
        handlers_(std::move(handlers)),
        stats_(std::move(stats)),
        timer_(socket_.get_executor()) {
    ++stats_->pending;
  }

  void Start() {
    timer_.expires_after(policy_.handshake_timeout);
    timer_.async_wait([self = this->shared_from_this()](const std::error_code& ec) {
      if (ec || self->done_) return;
      ++self->stats_->timed_out;
      // On loopback a client may connect and speak later (the Python clock's connection waits for
      // the test's first step): it becomes a session, whose number is bounded. Beyond loopback
      // silence is a refusal.
      if (!self->policy_.required) return self->Admit();
      self->Refuse("nothing received within " + std::to_string(self->policy_.handshake_timeout.count()) +
                   " ms");
    });
    WaitReadable();
  }

  void WaitReadable() {
    socket_.async_wait(asio::socket_base::wait_read,
                       [self = this->shared_from_this()](const std::error_code& ec) {
                         if (self->done_) return;
                         if (ec) return self->Drop();
                         self->Examine();
                       });
  }

  void Examine() {
    const ssize_t n =
        ::recv(socket_.native_handle(), buffer_.data(), buffer_.size(), MSG_PEEK | MSG_DONTWAIT);
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) return WaitReadable();
    if (n <= 0) return Drop();  // closed before saying anything, or reset
    const PreambleScan scan = ScanAuthPreamble(std::span(buffer_.data(), static_cast<std::size_t>(n)));
    switch (scan.kind) {
      case PreambleScan::Kind::kNone:
        if (policy_.required)
          return Refuse(
              "no token: this endpoint is reachable from other hosts and needs the fleet's token "
              "(CANFLEET_TOKEN_FILE, CANFLEET_TOKEN or --token-file)");
        return Admit();
      case PreambleScan::Kind::kMalformed:
        return Refuse("malformed auth preamble (token length outside " + std::to_string(kMinTokenLength) +
                      ".." + std::to_string(kMaxTokenLength) + ")");
      case PreambleScan::Kind::kPartial:
        return RetrySoon();
      case PreambleScan::Kind::kComplete:
        break;
    }
    const bool accepted = policy_.token.empty() ? !policy_.required : TokensEqual(policy_.token, scan.token);
    // The preamble is consumed (it is in the socket's buffer: this recv takes exactly it).
    const ssize_t taken = ::recv(socket_.native_handle(), buffer_.data(), scan.size, MSG_DONTWAIT);
    if (taken != static_cast<ssize_t>(scan.size)) return Drop();
    if (!accepted) return Refuse("wrong token");
    Admit();
  }

  /// The start of a preamble has come but not all of it: the socket stays readable, so look
  /// again a little later rather than spin on it.
  void RetrySoon() {
    auto retry = std::make_shared<asio::steady_timer>(socket_.get_executor(), std::chrono::milliseconds(5));
    retry->async_wait([self = this->shared_from_this(), retry](const std::error_code& ec) {
      if (!ec && !self->done_) self->Examine();
    });
  }

  void Admit() {
    done_ = true;
    timer_.cancel();
    ++stats_->admitted;
    handlers_.admit(std::move(socket_));
  }

  void Refuse(const std::string& reason) {
    done_ = true;
    ++stats_->refused;
    if (handlers_.log_refusal) handlers_.log_refusal(reason);
    if (handlers_.refusal) {
      // One non-blocking send: a refusal is a few dozen bytes and the socket's buffer is empty.
      const std::string bytes = handlers_.refusal(reason);
      [[maybe_unused]] const auto sent =
          ::send(socket_.native_handle(), bytes.data(), bytes.size(), MSG_DONTWAIT | MSG_NOSIGNAL);
    }
    // A lingering close: closing with the client's bytes unread would send a reset, and a reset
    // can destroy the refusal before the client reads it. So: end our side, read and discard
    // what the client sends until it closes (it does once it has read the refusal), for at most
    // kLinger and kMaxDiscard bytes.
    std::error_code ignored;
    socket_.shutdown(asio::socket_base::shutdown_send, ignored);
    timer_.expires_after(kLinger);
    timer_.async_wait([self = this->shared_from_this()](const std::error_code& ec) {
      if (!ec) self->Drop();
    });
    Discard();
  }

  void Discard() {
    socket_.async_wait(
        asio::socket_base::wait_read, [self = this->shared_from_this()](const std::error_code& ec) {
          if (ec || !self->socket_.is_open()) return;
          const ssize_t n =
              ::recv(self->socket_.native_handle(), self->buffer_.data(), self->buffer_.size(), MSG_DONTWAIT);
          if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) return self->Discard();
          self->discarded_ += n > 0 ? static_cast<std::size_t>(n) : 0;
          if (n <= 0 || self->discarded_ > kMaxDiscard) return self->Drop();
          self->Discard();
        });
  }

  void Drop() {
    done_ = true;
    timer_.cancel();
    std::error_code ignored;
    socket_.shutdown(asio::socket_base::shutdown_both, ignored);
    socket_.close(ignored);
  }

  Socket socket_;
  const AuthPolicy policy_;  // a copy: a gate may outlive its listener
  AuthGateHandlers<Socket> handlers_;
  std::shared_ptr<AuthGateStats> stats_;
  asio::steady_timer timer_;
  std::array<std::uint8_t, kMaxAuthPreamble> buffer_{};
  bool done_ = false;
  std::size_t discarded_ = 0;
  static constexpr std::chrono::milliseconds kLinger{1'000};
  static constexpr std::size_t kMaxDiscard = 1 << 20;
};

/// The policy of a listener at `address`: a token is required beyond loopback. Throws
/// std::runtime_error when it would be required and `token` is empty.
template <class Address>
AuthPolicy PolicyFor(const Address& address, const std::string& token, const std::string& what) {
  AuthPolicy policy;
  policy.required = !address.is_loopback();
  policy.token = token;
  if (policy.required && token.empty())
    throw std::runtime_error(
        what + " on " + address.to_string() +
        " is reachable from other hosts and needs the fleet's token: give one with "
        "--token-file, CANFLEET_TOKEN_FILE or CANFLEET_TOKEN (scripts/docker-fleet.sh makes "
        "one), or listen on 127.0.0.1");
  return policy;
}

}  // namespace canfleet::wire
