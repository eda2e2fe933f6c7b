#pragma once
/// @file The node's attachment to a virtual bus of the broker (design.md: "canfleet-node ...
/// --bus can0@tcp://host:port"): a BusPort over the node <-> broker protocol (bus/wire/).

#include <asio/io_context.hpp>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bus/broker_client/virtual_time_client.hpp"
#include "bus/bus_port.hpp"
#include "bus/wire/canfleet_wire.pb.h"

namespace canfleet {

struct BrokerClientOptions {
  /// `tcp://host:port` or `unix:///path` (bus/wire/endpoint.hpp).
  std::string endpoint = "tcp://127.0.0.1:29600";
  std::string bus = "can0";
  std::string node_name;      ///< for the broker's logs and statistics
  std::uint32_t node_id = 0;  ///< CANopen node-ID, 0 when none (a tool)
  /// The fleet's token (bus/wire/auth_token.hpp), sent first on a TCP connection: a broker
  /// listening beyond loopback lets in only clients that send it. Empty: none sent.
  std::string token{};
  /// Bus monitoring (a capture tool): receives every frame and error frame, never transmits or
  /// acknowledges. Send always returns false.
  bool monitor = false;
  /// Ask the broker for TX confirmations (OnTxConfirmed).
  bool tx_confirmations = false;
  /// The bit rate the controller runs at (bit/s, Hello.bitrate); 0 = not stated: the broker runs
  /// the port at its bus's rate. SetBitRate changes it.
  std::uint32_t bitrate = 0;
  /// Reconnection delays: the first retry after `initial_backoff`, doubling up to `max_backoff`;
  /// back to `initial_backoff` after a successful Hello.
  std::chrono::milliseconds initial_backoff{100};
  std::chrono::milliseconds max_backoff{5000};
  /// Connect + Hello/HelloReply must complete within this, or the attempt counts as failed.
  std::chrono::milliseconds handshake_timeout{5000};
  /// Frames waiting to be written to the socket; a Send beyond this returns false.
  std::size_t transmit_queue_frames = 65536;
  /// Lock-step virtual time (virtual_time_client.hpp): the process's client, which must outlive
  /// the port, and this port's index among the process's ports. nullptr: real time.
  VirtualTimeClient* virtual_time = nullptr;
  std::size_t virtual_time_index = 0;
};

/// What the broker told us when it accepted the Hello.
struct BrokerSession {
  std::uint32_t port_id = 0;
  std::uint32_t bitrate = 0;  ///< bit/s
  bool paced = true;
  bool virtual_time = false;
};

struct BrokerClientStats {
  std::uint64_t connects = 0;     ///< accepted Hellos
  std::uint64_t disconnects = 0;  ///< established connections lost
  std::uint64_t failed_attempts = 0;
  std::uint64_t tx_frames = 0;        ///< frames accepted by Send
  std::uint64_t tx_refused = 0;       ///< Send returned false
  std::uint64_t rx_frames = 0;        ///< frames delivered to OnReceive
  std::uint64_t rx_error_frames = 0;  ///< of those, error frames (CanFrame::kError)
  std::uint64_t writes = 0;           ///< socket writes (one per io_context turn at most)
  std::uint64_t partial_writes = 0;   ///< of those, taken only in part by the socket
  std::uint64_t reads = 0;            ///< socket reads
  std::uint64_t empty_reads = 0;      ///< of those, found nothing to read (EAGAIN)
  /// Virtual time: frames sent by a timer confined to another identifier (Timer::Confine); 0
  /// unless a node breaks its promise.
  std::uint64_t confinement_breaches = 0;
};

/// A BusPort on a broker's virtual bus, over TCP or a Unix-domain socket, driven by an
/// asio::io_context (all handlers run on the thread running it; a handler may destroy the port).
///
/// - Connects on construction (asynchronously) and sends Hello; frames flow once the broker
///   accepts it.
/// - Send appends the frame to an outgoing batch; the batch is written once per io_context turn,
///   so a burst of frames is one write. Buffers are reused: no allocation per frame.
/// - Received frames reach OnReceive with their bus time; controller events reach OnStateChange
///   and State(). Error frames (a node at another bit rate than its bus's sees them, README of
///   orchestrator/broker) reach OnReceive too, flagged CanFrame::kError; the first one after a
///   connection or a rate change is logged.
/// - When the broker goes away (or refuses the Hello), the port logs why and reconnects with
///   exponential backoff ("broker connection lost: ...; reconnecting in 400 ms"). While it is
///   disconnected Send returns false: the frames are lost, as on an unplugged cable. Each new
///   connection is a new controller: error-active, counters 0.
/// - In virtual time (BrokerClientOptions::virtual_time), what the broker sends is held until its
///   TimeGrant and applied then, frames leave stamped with the node's time, and every grant is
///   answered with TimeReached (virtual_time_client.hpp).
class BrokerClientPort final : public BusPort {
 public:
  /// `connected`: true once a Hello is accepted; false when that connection is lost, and also when
  /// the broker refuses the Hello (`detail` starts with "refused: "), which retrying may never cure
  /// (protocol version, unknown bus). Failed attempts to reach an absent broker are only logged.
  /// `detail`: "tcp://127.0.0.1:29600 bus can0 (500000 bit/s, paced), port 3" or why.
  using ConnectionHandler = std::function<void(bool connected, const std::string& detail)>;
  using TxConfirmHandler = std::function<void(const CanFrame&, BusTime)>;
  /// Answers one request of the broker to this node (simulated I/O: NodeRequest.io_set / io_get).
  /// Called on the io thread; the reply's request_id is filled in by the port. It may destroy the
  /// port (then nothing is sent).
  using NodeRequestHandler = std::function<wire::NodeReply(const wire::NodeRequest&)>;
  /// The 11-bit identifiers the node listens to (nullopt: every frame): its acceptance filter,
  /// which the broker applies to what it delivers. Virtual time: asked at the end of each grant, a
  /// change sent before TimeReached. Real time: asked before each write, a change sent first in
  /// that write. Until the first Acceptance of a connection the broker delivers every frame.
  using AcceptanceProvider = std::function<std::optional<std::vector<std::uint32_t>>()>;
  /// Of the identifiers the filter lets through, the heartbeats the node answers with nothing
  /// before a delay (wire::Acceptance.passive), sent with the filter; asked with it.
  using PassiveProvider = std::function<std::vector<std::pair<std::uint32_t, Duration>>()>;

  /// Throws std::invalid_argument on a malformed endpoint.
  BrokerClientPort(asio::io_context& io, BrokerClientOptions options);
  ~BrokerClientPort() override;
  BrokerClientPort(const BrokerClientPort&) = delete;
  BrokerClientPort& operator=(const BrokerClientPort&) = delete;

  /// False when disconnected, bus-off, a monitor, the frame is invalid or an error frame, or the
  /// transmit queue is full.
  bool Send(const CanFrame& frame) override;
  ControllerState State() const override;
  /// Sends BitRate to the broker now if connected (else the next Hello states it). False (and
  /// nothing changes) outside 10 000..1 000 000 bit/s.
  /// `bit_per_s` 0 returns the port to its bus's rate. Logs the change.
  bool SetBitRate(std::uint32_t bit_per_s) override;
  /// Real time: sends the filter now if it changed. Virtual time: the node checks it after every
  /// instant it runs (VirtualTimeClient).
  void AcceptanceMayHaveChanged() override;
  /// The rate stated to the broker (0 = none: the bus's rate).
  std::uint32_t BitRate() const;

  bool Connected() const;
  /// The current connection's parameters; nullopt while disconnected.
  std::optional<BrokerSession> Session() const;

  void OnConnection(ConnectionHandler handler);
  void OnTxConfirmed(TxConfirmHandler handler);
  /// Serves the broker's NodeRequests. Without a handler the port answers each with the error
  /// "<node name> serves no node requests", so the broker is not left waiting.
  void OnNodeRequest(NodeRequestHandler handler);
  void OnAcceptance(AcceptanceProvider provider);
  void OnPassive(PassiveProvider provider);

  const BrokerClientStats& Stats() const;

 private:
  class Link;
  std::shared_ptr<Link> link_;
};

}  // namespace canfleet
