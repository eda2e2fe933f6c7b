#pragma once
/// @file One socketcand client connection (internal to the server).
///
/// Modes, as socketcand's state machine (socketcand.c, state_nobus.c, state_raw.c):
///   - NO_BUS: "< hi >" on connect; only "< open BUS >" is understood: "< ok >" and BCM mode, or
///     "< error could not open bus >" and the connection is closed. Anything else:
///     "< error unknown command >".
///   - BCM: the default after open. "< rawmode >" / "< bcmmode >" switch modes ("< ok >");
///     "< send >", "< sendrtr >" and "< echo >" work; the broadcast-manager jobs (add, update,
///     delete, filter, muxfilter, subscribe, unsubscribe) are not served:
///     "< error command not supported >". No frames are forwarded in this mode.
///   - RAW: every frame of the other ports is forwarded; "< send >", "< sendrtr >", "< echo >".
///     A malformed send is logged and ignored (socketcand does not answer it); an unknown command
///     gets "< error unknown command >".
/// "< isotpmode >" and "< controlmode >" are answered "< error mode not supported >".
///
/// Robustness: elements longer than kMaxElementLength close the connection with a logged reason;
/// output for a slow client is bounded (frames beyond ServerOptions::max_output_bytes are dropped
/// and counted); a client sending faster than the bus carries is paused while its port's TX
/// queue holds ServerOptions::max_tx_backlog frames (its commands wait; reading stops 64 KiB
/// ahead, so TCP flow control slows the client). A client that closes the connection keeps its
/// port until the frames it sent are on the wire (at most ServerOptions::drain_timeout).

#include <array>
#include <asio/generic/stream_protocol.hpp>
#include <asio/io_context.hpp>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "clock/scheduler.hpp"
#include "orchestrator/broker/port_sink.hpp"
#include "orchestrator/socketcand/protocol.hpp"
#include "orchestrator/socketcand/server.hpp"
#include "orchestrator/transport/slow_reader.hpp"

namespace canfleet::socketcand::detail {

class Session;

/// What the server and its listeners and sessions share. Handlers hold it by shared_ptr, so it
/// outlives the Server while operations are pending; `stopped` tells them to do nothing.
struct Context {
  Context(asio::io_context& io_context, broker::Broker& b, Scheduler& s, ServerOptions o)
      : io(io_context), broker(b), scheduler(s), options(std::move(o)) {}

  asio::io_context& io;
  broker::Broker& broker;
  Scheduler& scheduler;  ///< the broker's: every timer of the endpoint
  ServerOptions options;
  WallTime origin{};
  std::vector<std::string> buses;  ///< the buses served
  std::vector<std::shared_ptr<Session>> sessions;
  ServerStats stats;
  bool stopped = false;

  bool Serves(std::string_view bus) const;
};

class Session final : public broker::PortSink, public std::enable_shared_from_this<Session> {
 public:
  /// `listener_bus`: the bus of the port the client connected to, and `peer` the client
  /// ("127.0.0.1:40312"), for log lines ("socketcand can0 127.0.0.1:40312: ...").
  Session(std::shared_ptr<Context> context, asio::generic::stream_protocol::socket socket,
          std::string_view listener_bus, std::string peer);
  ~Session() override;

  /// Greets the client and starts reading.
  void Start();
  /// Detaches the port and closes the socket now, logging `reason`. Idempotent.
  void Close(std::string_view reason);
  bool closed() const { return closed_; }

  void Deliver(std::span<const broker::TimedFrame> frames) override;
  void ControllerChanged(const ControllerEvent& event) override;
  void TxConfirmed(std::span<const broker::TimedFrame> frames) override;

 private:
  enum class Mode : std::uint8_t { kNoBus, kBcm, kRaw };

  void Read();
  void OnRead(const asio::error_code& ec, std::size_t n);
  void Process();
  /// The client closed its side: its buffered commands are still carried out, and the session
  /// stays on the bus until its frames are on the wire (a CAN driver sends what was queued
  /// before the socket closed), at most ServerOptions::drain_timeout.
  void StartDrain();
  void CheckDrained();
  void OnDrainTimeout();
  void Handle(std::string_view element);
  void Open(std::string_view bus);
  void SubmitFrame(const CanFrame& frame);
  bool BacklogFull();
  void ScheduleResume();
  void ProtocolError(std::string_view element, std::string_view why);

  /// Queues a reply. `pad`: aligned like frames (raw mode), false for handshake replies.
  void Reply(std::string_view message, bool pad);
  /// Replies and closes the connection once the reply is written.
  void Fail(std::string_view message, std::string reason);
  void EnterRaw();
  void ReleaseHeld();
  void Write();
  void OnWrite(const asio::error_code& ec, std::size_t n);

  std::shared_ptr<Context> ctx_;
  asio::generic::stream_protocol::socket socket_;
  std::string peer_;  ///< "127.0.0.1:40312"
  std::string name_;  ///< prefix of log lines
  Mode mode_ = Mode::kNoBus;
  broker::PortId port_ = 0;

  ElementReader reader_;
  std::array<char, 4096> read_buffer_{};
  bool reading_ = false;
  bool paused_ = false;  ///< not executing commands: the port's TX backlog is full
  bool draining_ = false;
  /// ServerOptions::drain_timeout, from the first check after the client closed its side. The
  /// session's timers are destroyed by Close(): the session itself may outlive the scheduler
  /// (pending I/O handlers hold it), its timers may not.
  std::optional<Timer> drain_timer_;
  std::size_t tx_backlog_ = 0;

  std::string pending_;  ///< queued for the client
  std::string writing_;  ///< being written (never appended to while a write is in flight)
  std::size_t written_ = 0;
  bool write_active_ = false;
  std::uint64_t queued_bytes_ = 0;   ///< total appended to pending_
  std::uint64_t written_bytes_ = 0;  ///< total written to the socket
  /// Frames dropped for a slow client; disconnected after ServerOptions::slow_client_limit.
  transport::SlowReader slow_;
  bool slow_close_posted_ = false;

  /// Raw-mode settle (ServerOptions::raw_settle): frames go to held_ until the "< ok >" has been
  /// written (written_bytes_ reaches settle_after_) and the settle time has passed.
  bool holding_ = false;
  std::optional<std::uint64_t> settle_after_;
  std::string held_;
  std::optional<Timer> settle_timer_;

  bool closing_ = false;  ///< close once everything queued is written
  std::string closing_reason_;
  bool closed_ = false;
  std::uint64_t protocol_errors_ = 0;
};

}  // namespace canfleet::socketcand::detail
