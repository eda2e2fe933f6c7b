#pragma once
/// @file The socketcand endpoint (design decision 7, open doors): each broker bus can be served on
/// its own TCP port with the socketcand raw-mode protocol, so python-can
/// (`interface='socketcand'`), python-canopen and any other socketcand client join the virtual bus.
///
/// Each client session that opens a bus is one broker port: what the client sends is Submit()ed
/// as that port's frames, and every frame of the other ports is written to the client (its own
/// frames are not echoed back, as a SocketCAN raw socket does not receive its own frames).
/// See protocol.hpp for the protocol and session.hpp for a session's rules.
///
/// Threading: everything runs on the thread of the io_context, which must also drive the
/// broker's Scheduler (an AsioScheduler on the same io_context, or a SimulatedScheduler the same
/// thread advances: unit tests). Every timer of the endpoint (raw-mode settle, drain timeout,
/// accept retry) is a Timer on that scheduler.

#include <asio/generic/stream_protocol.hpp>
#include <asio/io_context.hpp>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "clock/scheduler.hpp"
#include "orchestrator/broker/broker.hpp"
#include "orchestrator/socketcand/protocol.hpp"

namespace canfleet::socketcand {

struct ServerOptions {
  /// Address the listeners bind to. Loopback by default: serving other hosts is an explicit
  /// choice ("0.0.0.0").
  std::string bind_address = "127.0.0.1";
  /// Pad every message of raw mode to 64-byte records (see AppendFrame), so that python-can 4.1.0
  /// (Debian 12's python3-can) does not lose frames; any other client ignores the padding.
  bool align_frames = true;
  /// How long frames are held after the "< ok >" that answers "< rawmode >" has been written.
  /// python-can reads that reply with one recv() and compares it exactly, so a frame arriving in
  /// the same read would fail its handshake. Held frames are sent afterwards, none is lost.
  /// Zero: no hold.
  Duration raw_settle = std::chrono::milliseconds(50);
  /// Bytes a session may have waiting for a slow client. Frames beyond are dropped and counted
  /// (as a SocketCAN socket's full receive queue drops them), never buffered without bound.
  std::size_t max_output_bytes = std::size_t{4} << 20;
  /// Sessions open at once (every bus of the server): beyond, a new client gets
  /// "< error too many connections >" and is closed. With max_output_bytes, this bounds the memory
  /// clients that do not read can take.
  std::size_t max_sessions = 32;
  /// A client whose output has stayed full this long (frames dropped all along) is disconnected
  /// with the reason logged (transport/slow_reader.hpp).
  std::chrono::milliseconds slow_client_limit{10'000};
  /// Frames a session may have waiting in its port's TX queue. Beyond, the session stops reading
  /// from its client until the bus has taken some (TCP backpressure instead of drops).
  std::size_t max_tx_backlog = 256;
  /// After a client closes its connection, its port stays on the bus until the frames it sent
  /// are on the wire (as a CAN driver sends what was queued before its socket closed), at most
  /// this long: a port alone on a bus never gets its frames acknowledged.
  Duration drain_timeout = std::chrono::seconds(2);
  /// Wall-clock time of bus time 0, for the frames' timestamps. Default: read from the system
  /// clock when the server is created (WallClockOrigin, clock/wall_clock.hpp). A process that also
  /// captures gives its one origin here (host::BrokerHost does), so both stamp a frame alike.
  std::optional<WallTime> wall_origin;
};

/// Counters over all sessions of a server.
struct ServerStats {
  std::uint64_t sessions_accepted = 0;
  std::size_t sessions_open = 0;
  std::uint64_t frames_to_clients = 0;    ///< frames written to clients
  std::uint64_t frames_from_clients = 0;  ///< frames accepted by the broker
  std::uint64_t output_drops = 0;         ///< frames dropped for a slow client (max_output_bytes)
  std::uint64_t sessions_refused = 0;     ///< clients refused beyond max_sessions
  std::uint64_t slow_clients = 0;         ///< clients disconnected for not reading (slow_client_limit)
  std::uint64_t submit_drops = 0;         ///< client frames the broker refused (bus-off, queue full)
  std::uint64_t protocol_errors = 0;      ///< malformed or unsupported commands
};

namespace detail {
struct Context;
struct Listener;
}  // namespace detail

class Server {
 public:
  /// `broker` must outlive the server and run on `io` (its scheduler an AsioScheduler on `io`, or
  /// a SimulatedScheduler advanced by the thread that runs `io`). `scheduler` is the broker's: the
  /// endpoint's timers run on it, and its time 0 is mapped to the wall clock for the frames'
  /// timestamps (unless ServerOptions::wall_origin says otherwise). It must outlive the server.
  Server(asio::io_context& io, broker::Broker& broker, Scheduler& scheduler, ServerOptions options = {});
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  /// Starts serving `bus` on `port`; returns the port bound. Without a port: kDefaultPort for the
  /// first bus served, kDefaultPort + 1 for the second, ...; port 0: an ephemeral port (tests).
  /// A client of any listener may open any bus this server serves (like socketcand, which serves
  /// several buses on one port); a bus's own port is where its clients go by default.
  /// Throws std::invalid_argument for a bus the broker does not have or that is already served,
  /// std::system_error when the address cannot be bound.
  std::uint16_t Serve(std::string_view bus, std::optional<std::uint16_t> port = std::nullopt);

  /// Lets clients open `bus` without a listener of its own: clients of Adopt(), or of another
  /// bus's listener. Throws std::invalid_argument as Serve() does.
  void Offer(std::string_view bus);

  /// Serves a client connected by other means than a listener (one end of a socketpair in unit
  /// tests, an inherited descriptor) as if it had connected to `bus`'s port. `peer` names it in
  /// log lines. Throws std::invalid_argument for a bus this server does not serve.
  void Adopt(asio::generic::stream_protocol::socket socket, std::string_view bus, std::string peer);

  /// Closes the listeners and every session (their ports are detached). Idempotent.
  void Stop();

  ServerStats Stats() const;

 private:
  /// Throws std::invalid_argument for a bus the broker does not have or that is already served.
  void CheckServable(std::string_view bus) const;

  std::shared_ptr<detail::Context> context_;
  std::vector<std::shared_ptr<detail::Listener>> listeners_;
};

}  // namespace canfleet::socketcand
