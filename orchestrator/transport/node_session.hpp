#pragma once
/// @file One connection of a node to the broker: the protocol state machine and the broker port
/// it attaches. Internal to BrokerServer.

#include <spdlog/spdlog.h>

#include <sys/uio.h>
#include <array>

#include <asio/generic/stream_protocol.hpp>
#include <asio/steady_timer.hpp>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "bus/wire/message_writer.hpp"
#include "bus/wire/stream_decoder.hpp"
#include "orchestrator/broker/broker.hpp"
#include "orchestrator/transport/broker_server.hpp"
#include "orchestrator/transport/slow_reader.hpp"
#include "orchestrator/transport/time_conductor.hpp"

namespace canfleet::transport::detail {

/// A session follows asio's chat_server (style.md, "Asio lifetimes"): it is owned by shared_ptrs,
/// every handler captures [this, self], and at most one write is in flight. Outgoing messages
/// accumulate in one reused buffer while a write is in flight (the queue of batches, without an
/// allocation per batch) and leave in the next write.
///
/// As a PortSink it only appends to that buffer and schedules a flush for the end of the current
/// io_context turn, so everything one broker round produced for this port goes out in one write.
///
/// In virtual time (BrokerServerOptions::time_conductor) a node's session is a GrantedSession: its
/// Hello is accepted between rounds, its frames go to the conductor with their times, and what is
/// sent to it makes it take part in the next round.
class NodeSession final : public std::enable_shared_from_this<NodeSession>,
                          public broker::PortSink,
                          public GrantedSession {
 public:
  using ClosedHandler = std::function<void(NodeSession*)>;

  /// `attach_counter`: the server's counter of accepted Hellos (AttachOrder); outlives the
  /// session's Hello.
  NodeSession(broker::Broker& broker, const BrokerServerOptions& options,
              std::shared_ptr<BrokerServerStats> stats, asio::generic::stream_protocol::socket socket,
              std::string label, ClosedHandler on_closed, std::uint64_t* attach_counter);
  ~NodeSession() override;

  void Start();

  /// What happens to the connection when the session ends.
  enum class Farewell : std::uint8_t {
    kNone,   ///< close now (the peer left, or the socket failed)
    kDrain,  ///< write what is queued (a refusing HelloReply), then close
    kError,  ///< drop what is queued, write Error{reason}, then close
  };
  /// Ends the session once: detaches the port, then closes the socket as `farewell` says (within
  /// BrokerServerOptions::close_linger at most). `level` is the log level of the reason.
  void Close(const std::string& reason, Farewell farewell, spdlog::level::level_enum level);

  /// Attached to a bus and not closed.
  bool Attached() const { return port_ != 0 && !closed_; }
  const std::string& Bus() const override { return bus_; }
  const std::string& NodeName() const { return node_name_; }
  /// Order of the accepted Hello among the server's sessions (later = larger).
  std::uint64_t AttachOrder() const { return attach_order_; }

  /// Sends a NodeRequest (BrokerServer::RequestNode documents `done`).
  void Request(wire::NodeRequest request, NodeReplyHandler done);

  // broker::PortSink
  void Deliver(std::span<const broker::TimedFrame> frames) override;
  /// Copies the runs from the round's wire encoding, made once per round for every session.
  void DeliverShared(const broker::SharedRound& round, std::span<const broker::FrameRun> runs) override;
  void ControllerChanged(const ControllerEvent& event) override;
  void TxConfirmed(std::span<const broker::TimedFrame> frames) override;

  // GrantedSession
  void SendGrant(TimePoint now, TimePoint until, std::span<const std::uint64_t> attachments) override;
  void Evict(const std::string& reason) override;
  const std::string& Label() const override { return label_; }
  const Acceptance& Accepting() const override { return acceptance_; }

 private:
  /// Attaches the port and answers the Hello (between rounds in virtual time).
  void Accept(const wire::Hello& hello);
  /// Something was queued for the node: in real time it leaves at the end of this turn; in
  /// virtual time it happened now, and leaves with the grant of the next round.
  /// `reacts_after`: what was queued makes the node send nothing before this (heartbeats it only
  /// watches, Acceptance::Passive); 0: it may answer at once.
  void Queued(Duration reacts_after = Duration::zero()) {
    if (granted_) {
      options_.time_conductor->Pending(*this, reacts_after);
      return;
    }
    if (driven_) options_.time_conductor->Wake();  // the driver's step ends where this happened
    ScheduleFlush();
  }
  /// Reads what the socket holds, then waits for more (bus/wire/socket_io.hpp).
  void Read();
  void WaitReadable();
  void Handle(const wire::Message& message);
  void OnHello(const wire::Hello& hello);
  void OnNodeReply(const wire::NodeReply& reply);
  /// BitRate: the node's controller switched rate (0: back to the bus's).
  void OnBitRate(std::uint32_t bitrate);
  /// Closing: every pending request ends with nullopt.
  void FailPendingRequests();
  void Refuse(const std::string& reason);
  void ProtocolError(const std::string& reason);
  void ScheduleFlush();
  /// Writes filling_ now; what the socket does not take goes on through WriteRest.
  void Flush();
  /// One sendmsg of `message`, which starts with filling_'s bytes (if any): on success filling_
  /// is empty; what the socket did not take is copied into writing_ for WriteRest.
  void SendNow(std::span<const iovec> message);
  /// Writes a delivery straight from the round's shared encoding (with filling_ before it).
  void WriteGathered(const std::uint8_t* records, std::span<const broker::FrameRun> runs, std::size_t frames);
  /// Writes writing_ asynchronously (one write in flight), then whatever collected meanwhile.
  void WriteRest();
  /// Everything queued has left: finish a lingering close, end a backlog episode.
  void Written();
  void CloseSocket();

  broker::Broker& broker_;
  const BrokerServerOptions options_;
  std::shared_ptr<BrokerServerStats> stats_;
  asio::generic::stream_protocol::socket socket_;
  asio::steady_timer timer_;  ///< Hello deadline, then close linger
  std::string label_;         ///< "session 3 (quad-5 on can0, port 7, tcp 127.0.0.1:40312)"
  ClosedHandler on_closed_;

  broker::PortId port_ = 0;  ///< 0 until a Hello is accepted
  std::string bus_;          ///< from the accepted Hello
  std::string node_name_;    ///< from the accepted Hello ("" when it gave none)
  std::uint64_t* attach_counter_;
  std::uint64_t attach_order_ = 0;
  bool tx_confirmations_ = false;
  bool closed_ = false;
  bool hello_seen_ = false;  ///< a Hello arrived (in virtual time it is accepted between rounds)
  bool granted_ = false;     ///< a node in virtual time: the conductor grants its time
  bool driven_ = false;      ///< a participant of the process that drives time (Hello.driven)
  /// The node's acceptance filter (wire::Acceptance), in real and virtual time; until it sends
  /// one, every frame.
  Acceptance acceptance_;
  /// Whether `frame` passes the filter (extended and error frames always do).
  bool Accepts(const CanFrame& frame) const { return acceptance_.Accepts(frame); }
  /// How long after `frame` arrives the node may answer it at the earliest (a heartbeat it only
  /// watches: its delay; anything else: 0).
  Duration ReactsAfter(const CanFrame& frame) const {
    return IsHeartbeat(frame) ? acceptance_.DelayOf(frame.id) : Duration::zero();
  }
  SendOutlook outlook_;                       ///< of the last TimeReached (reused)
  std::vector<Acceptance::Passive> passive_;  ///< of the last Acceptance (reused)

  wire::StreamDecoder decoder_;
  wire::Message message_;
  std::vector<CanFrame> submit_;             ///< frames of one received batch, reused
  std::vector<wire::StampedFrame> stamped_;  ///< the same in virtual time, with their times

  /// Runs per gathered write (the iovec array); a delivery cut into more (many per-receiver
  /// exceptions of the fault stage) is copied into filling_ instead.
  static constexpr std::size_t kMaxGatherRuns = 30;
  std::array<std::uint8_t, wire::kMaxBatchHeader> header_{};  ///< of the gathered Frames message

  wire::MessageWriter filling_;  ///< waiting for the next write
  wire::MessageWriter writing_;  ///< the unwritten rest of a write the socket took only in part
  bool write_in_flight_ = false;
  bool flush_posted_ = false;
  /// Frames dropped for a full backlog; disconnects after BrokerServerOptions::slow_reader_limit.
  SlowReader slow_;
  void Overflow(std::size_t frames);

  /// NodeRequests waiting for their reply, by the id this session gave them.
  struct PendingRequest {
    std::uint64_t caller_id = 0;  ///< the caller's request_id, restored in the reply
    NodeReplyHandler done;
    std::unique_ptr<asio::steady_timer> deadline;
  };
  std::unordered_map<std::uint64_t, PendingRequest> pending_;
  std::uint64_t next_request_ = 1;
};

}  // namespace canfleet::transport::detail
