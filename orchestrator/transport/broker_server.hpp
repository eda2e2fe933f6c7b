#pragma once
/// @file Serves a Broker's buses to node processes over the node <-> broker protocol
/// (bus/wire/canfleet_wire.proto), on TCP and Unix-domain sockets.

#include <asio/generic/stream_protocol.hpp>
#include <asio/io_context.hpp>
#include <asio/ip/tcp.hpp>
#include <asio/local/stream_protocol.hpp>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "bus/wire/auth_gate.hpp"
#include "bus/wire/endpoint.hpp"
#include "bus/wire/messages.hpp"
#include "clock/wall_clock.hpp"
#include "orchestrator/broker/broker.hpp"

namespace canfleet::transport {

namespace detail {
class NodeSession;
}
class TimeConductor;

struct BrokerServerOptions {
  /// Bytes a session may have waiting for a slow reader; deliveries beyond it are dropped and
  /// counted (a receiver that does not read loses frames, like a CAN controller's overrun).
  std::size_t max_backlog_bytes = std::size_t{16} << 20;
  /// A session whose backlog has stayed full this long (frames dropped all along) is
  /// disconnected with the reason logged (transport/slow_reader.hpp); its node reconnects.
  std::chrono::milliseconds slow_reader_limit{10'000};
  /// A connection that has not sent its Hello by then is closed.
  std::chrono::milliseconds hello_timeout{10'000};
  /// After a protocol error, how long the Error message may take to leave before the socket is
  /// closed anyway.
  std::chrono::milliseconds close_linger{1'000};
  /// RequestNode gives up (nullopt) when the node has not answered by then.
  std::chrono::milliseconds node_request_timeout{3'000};
  /// Lock-step virtual time (time_conductor.hpp): the conductor of every bus of this broker, which
  /// must outlive the server. nullptr: real time.
  TimeConductor* time_conductor = nullptr;
  /// The wall-clock time of bus time 0 (clock/wall_clock.hpp), told to every client in its
  /// HelloReply (wall_origin_ns) so that it stamps received frames as captures do. The epoch (0)
  /// in virtual time and when unknown.
  WallTime wall_origin{};
  /// The fleet's token (bus/wire/auth_token.hpp). A TCP listener beyond loopback needs one, and
  /// its clients must send it before their Hello (wire/auth_gate.hpp); Unix sockets need none.
  std::string token{};
  /// TCP connections waiting at the gate at once; one more is closed at once.
  std::size_t max_pending = 64;
  /// Sessions at once (every bus of this broker: up to 127 nodes each, plus tools); one more is
  /// refused with a HelloReply saying so.
  std::size_t max_sessions = 1024;
};

struct BrokerServerStats {
  std::uint64_t accepted = 0;             ///< connections accepted
  std::uint64_t attached = 0;             ///< Hellos accepted
  std::uint64_t refused = 0;              ///< Hellos refused (version, unknown bus, bad names)
  std::uint64_t refused_connections = 0;  ///< refused before a Hello: no or wrong token, too many
  std::uint64_t protocol_errors = 0;      ///< connections closed for malformed or out-of-order data
  std::uint64_t backlog_drops = 0;        ///< frames not sent to slow readers
  std::uint64_t slow_readers = 0;         ///< sessions closed for not reading (slow_reader_limit)
  std::uint64_t filtered_frames = 0;      ///< frames not sent to a node whose acceptance filter rejects them
  std::uint64_t node_requests = 0;        ///< RequestNode calls
  std::uint64_t node_replies = 0;         ///< of those, answered by the node (error or not)
  std::uint64_t reads = 0;                ///< recv calls on sessions
  std::uint64_t empty_reads = 0;          ///< of those, found nothing to read (EAGAIN)
  std::uint64_t writes = 0;               ///< send calls on sessions
  std::uint64_t gathered_writes = 0;      ///< of those, straight from a round's shared encoding
  std::uint64_t partial_writes = 0;       ///< of those, taken only in part by the socket (slow reader)
};

/// Called once per RequestNode: the node's reply, or nullopt when no node of that name is
/// attached to that bus, it disconnected first, or it did not answer within
/// BrokerServerOptions::node_request_timeout.
using NodeReplyHandler = std::function<void(std::optional<wire::NodeReply>)>;

/// Accepts connections and runs one session per connection: a valid Hello attaches a port to the
/// named bus (Broker::Attach), frames it sends are submitted, and what the broker delivers to the
/// port (frames, controller events, TX confirmations) is written back in batches, one write in
/// flight per connection. A malformed, oversized or out-of-order message closes that connection
/// with a logged reason; the broker and the other sessions carry on.
///
/// Threading: everything runs on the thread running `io`, which must also drive the Broker's
/// scheduler (AsioScheduler on the same io_context).
class BrokerServer {
 public:
  BrokerServer(asio::io_context& io, broker::Broker& broker, BrokerServerOptions options = {});
  /// Closes every session (detaching their ports) and the listeners.
  ~BrokerServer();
  BrokerServer(const BrokerServer&) = delete;
  BrokerServer& operator=(const BrokerServer&) = delete;

  /// Starts accepting on `endpoint` and returns where it listens (the real port when `endpoint`
  /// asks for port 0). A TCP address other than loopback must be asked for explicitly; it is
  /// logged as reachable from other hosts. For a Unix socket, a stale socket file (nobody
  /// listening) is replaced. Throws std::system_error when binding fails and
  /// std::runtime_error when another process listens on the socket path.
  wire::Endpoint Listen(const wire::Endpoint& endpoint);

  /// Stops accepting and closes every session. Unix socket files created by Listen are removed.
  /// Pending RequestNode calls get their nullopt before this returns.
  void Close();

  /// Sends `request` to the node attached to `bus` under `node_name` (Hello.node_name; the most
  /// recent attachment if several carry that name) and calls `done` with its reply, whose
  /// request_id is the one of `request` (the server numbers what it sends itself, so callers need
  /// not make ids unique). `done` is called exactly once, on the io thread, never from inside
  /// this call: with nullopt when the node is unknown, disconnects before answering, the server
  /// closes, or the timeout passes. A reply with a non-empty `error` is the node's refusal
  /// ("unknown signal ...").
  void RequestNode(std::string_view bus, std::string_view node_name, wire::NodeRequest request,
                   NodeReplyHandler done);

  std::size_t SessionCount() const { return sessions_.size(); }
  const std::vector<wire::Endpoint>& Endpoints() const { return endpoints_; }
  /// The fleet's token (BrokerServerOptions::token), for the listeners opened after this call.
  void SetToken(std::string token) { options_.token = std::move(token); }
  const wire::AuthGateStats& GateStats() const { return *gate_stats_; }
  const BrokerServerStats& Stats() const { return *stats_; }

 private:
  void AcceptTcp(std::size_t index);
  void AcceptUnix(std::size_t index);
  void OnAccept(const asio::error_code& ec, std::string peer, asio::generic::stream_protocol::socket socket);
  /// Passes a TCP client through the auth gate (wire/auth_gate.hpp) to OnAccept.
  void Gate(std::size_t index, std::string peer, asio::ip::tcp::socket socket);
  void Remove(detail::NodeSession* session);

  asio::io_context& io_;
  broker::Broker& broker_;
  BrokerServerOptions options_;
  std::shared_ptr<BrokerServerStats> stats_ =
      std::make_shared<BrokerServerStats>();  ///< shared with the sessions
  /// Owned by the server alone: acceptor handlers that outlive it see it expired.
  std::shared_ptr<int> alive_ = std::make_shared<int>(0);
  std::vector<std::unique_ptr<asio::ip::tcp::acceptor>> tcp_;
  std::vector<wire::AuthPolicy> tcp_policies_;  ///< one per TCP acceptor
  std::shared_ptr<wire::AuthGateStats> gate_stats_ = std::make_shared<wire::AuthGateStats>();
  bool gate_full_logged_ = false;
  std::vector<std::unique_ptr<asio::local::stream_protocol::acceptor>> unix_;
  std::vector<std::string> unix_paths_;  ///< socket files to remove on Close
  std::vector<wire::Endpoint> endpoints_;
  std::unordered_map<detail::NodeSession*, std::shared_ptr<detail::NodeSession>> sessions_;
  std::uint64_t next_session_ = 1;
  std::uint64_t next_attach_ = 1;  ///< attach order of sessions (RequestNode picks the latest)
  bool closed_ = false;
};

}  // namespace canfleet::transport
