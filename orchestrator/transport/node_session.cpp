#include "orchestrator/transport/node_session.hpp"

#include <array>
#include <asio/post.hpp>
#include <asio/write.hpp>
#include <stdexcept>

#include "bus/physics/wire_model.hpp"
#include "bus/wire/frame_record.hpp"
#include "bus/wire/socket_io.hpp"
#include "orchestrator/transport/round_encoding.hpp"

namespace canfleet::transport::detail {

namespace {

constexpr std::size_t kReadChunk = 64 * 1024;

asio::const_buffer Buffer(std::span<const std::uint8_t> s) {
  return {s.data(), s.size()};
}

wire::StampedFrame Stamped(const broker::TimedFrame& f) {
  return {f.frame, f.time};
}

/// 0 (the bus's rate) or a rate the broker accepts (bus/physics/wire_model.hpp).
bool ValidBitrate(std::uint32_t bitrate) {
  return bitrate == 0 || (bitrate >= kMinBitrate && bitrate <= kMaxBitrate);
}

/// ", at 250000 bit/s on a 500000 bit/s bus" when a node states another rate than its bus's.
std::string RateNote(std::uint32_t bitrate, std::uint32_t bus) {
  if (bitrate == 0 || bitrate == bus) return {};
  return ", at " + std::to_string(bitrate) + " bit/s on a " + std::to_string(bus) + " bit/s bus";
}

std::string JoinBuses(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names)
    out += (out.empty() ? "" : ", ") + n;
  return out.empty() ? "none" : out;
}

}  // namespace

NodeSession::NodeSession(broker::Broker& broker, const BrokerServerOptions& options,
                         std::shared_ptr<BrokerServerStats> stats,
                         asio::generic::stream_protocol::socket socket, std::string label,
                         ClosedHandler on_closed, std::uint64_t* attach_counter)
    : broker_(broker),
      options_(options),
      stats_(std::move(stats)),
      socket_(std::move(socket)),
      timer_(socket_.get_executor()),
      label_(std::move(label)),
      on_closed_(std::move(on_closed)),
      attach_counter_(attach_counter),
      slow_(options.slow_reader_limit) {}

NodeSession::~NodeSession() {
  // Close() detaches before the last reference goes; this only guards a session that never ran.
  if (port_ != 0 && !closed_) broker_.Detach(port_);
}

void NodeSession::Start() {
  spdlog::debug("{}: connected", label_);
  timer_.expires_after(options_.hello_timeout);
  timer_.async_wait([this, self = shared_from_this()](const asio::error_code& ec) {
    if (ec || closed_ || port_ != 0) return;
    stats_->protocol_errors++;
    Close("no Hello within " + std::to_string(options_.hello_timeout.count()) + " ms", Farewell::kError,
          spdlog::level::warn);
  });
  Read();
}

void NodeSession::Read() {
  // One read, then (once the socket is drained) a wait for readiness; see bus/wire/socket_io.hpp.
  // The wait is armed in the same handler as the read that found the socket drained, so anything
  // that arrives later raises a readiness event the wait is there to see.
  const std::span<std::uint8_t> space = decoder_.WritableSpace(kReadChunk);
  std::error_code ec;
  const std::size_t n = wire::ReceiveNow(socket_.native_handle(), space, ec);
  stats_->reads++;
  if (wire::WouldBlock(ec)) {
    stats_->empty_reads++;
    WaitReadable();
    return;
  }
  if (ec) {
    Close(ec == wire::EndOfStream() ? "peer disconnected" : ec.message(), Farewell::kNone,
          spdlog::level::info);
    return;
  }
  decoder_.Commit(n);
  for (;;) {
    const auto result = decoder_.Next(message_);
    if (result == wire::StreamDecoder::Result::kNeedMore) break;
    if (result == wire::StreamDecoder::Result::kError) {
      ProtocolError(decoder_.Error());
      return;
    }
    Handle(message_);
    if (closed_) return;
  }
  if (n < space.size()) {
    WaitReadable();
    return;
  }
  // The chunk was full: more may be waiting. Read it after the handlers already queued (other
  // sessions, the broker's round), as async_read_some would, so one busy peer cannot starve them.
  asio::post(socket_.get_executor(), [this, self = shared_from_this()] {
    if (!closed_) Read();
  });
}

void NodeSession::WaitReadable() {
  socket_.async_wait(asio::socket_base::wait_read,
                     [this, self = shared_from_this()](const asio::error_code& ec) {
                       if (closed_) return;
                       if (ec) {
                         Close(ec.message(), Farewell::kNone, spdlog::level::info);
                         return;
                       }
                       Read();
                     });
}

void NodeSession::Handle(const wire::Message& m) {
  using wire::MessageType;
  if (port_ == 0 && m.type != MessageType::kHello && m.type != MessageType::kPing &&
      m.type != MessageType::kError) {
    ProtocolError(std::string(wire::ToString(m.type)) + " before Hello");
    return;
  }
  switch (m.type) {
    case MessageType::kHello:
      if (port_ != 0 || hello_seen_) {
        ProtocolError("second Hello");
        return;
      }
      hello_seen_ = true;
      OnHello(m.envelope.hello());
      return;
    case MessageType::kFrames: {
      if (granted_) {
        stamped_.resize(m.frames.size());
        for (std::size_t i = 0; i < m.frames.size(); ++i)
          stamped_[i] = m.frames[i];
        options_.time_conductor->Submit(*this, port_, stamped_);
        return;
      }
      submit_.resize(m.frames.size());
      for (std::size_t i = 0; i < m.frames.size(); ++i)
        submit_[i] = m.frames[i].frame;
      broker_.Submit(port_, submit_);  // refusals (bus-off, full queue) are counted by the broker
      return;
    }
    case MessageType::kPing:
      filling_.AddPong(m.envelope.ping().nonce());
      ScheduleFlush();
      return;
    case MessageType::kPong:
      return;
    case MessageType::kError:
      Close("peer closed the connection: " + m.envelope.error().reason(), Farewell::kNone,
            spdlog::level::info);
      return;
    case MessageType::kNodeReply:
      OnNodeReply(m.envelope.node_reply());
      return;
    case MessageType::kBitRate:
      OnBitRate(m.envelope.bit_rate().bitrate());
      return;
    case MessageType::kTimeReached: {
      const auto& reached = m.envelope.time_reached();
      const auto next = reached.has_deadline()
                            ? std::optional(TimePoint(Duration(reached.next_deadline_ns())))
                            : std::nullopt;
      const SendOutlook* outlook = nullptr;
      if (reached.has_outlook()) {
        outlook_.any =
            reached.has_any() ? std::optional(TimePoint(Duration(reached.any_ns()))) : std::nullopt;
        outlook_.confined.clear();
        for (const auto& c : reached.confined()) {
          const TimePoint deadline(Duration(c.deadline_ns()));
          if (c.id() <= 0x7FF)
            outlook_.confined.push_back({c.id(), deadline, c.heartbeat()});
          else  // not an 11-bit identifier: taken as anything
            outlook_.any = std::min(outlook_.any.value_or(deadline), deadline);
        }
        outlook = &outlook_;
      }
      if (!granted_ ||
          !options_.time_conductor->Reached(*this, TimePoint(Duration(reached.time_ns())), next, outlook))
        ProtocolError("TimeReached at " + std::to_string(reached.time_ns()) +
                      " ns without a grant to that time");
      return;
    }
    case MessageType::kAcceptance: {
      const auto& acceptance = m.envelope.acceptance();
      passive_.clear();
      for (const auto& p : acceptance.passive())
        if (p.delay_ns() > 0) passive_.push_back({p.id(), Duration(p.delay_ns())});
      acceptance_.Set(acceptance.all(),
                      {acceptance.ids().data(), static_cast<std::size_t>(acceptance.ids().size())}, passive_);
      return;
    }
    case MessageType::kTimeGrant:
    case MessageType::kHelloReply:
    case MessageType::kTxConfirm:
    case MessageType::kControllerEvent:
    case MessageType::kNodeRequest:
      ProtocolError(std::string("unexpected ") + wire::ToString(m.type) + " from a node");
      return;
  }
}

void NodeSession::Request(wire::NodeRequest request, NodeReplyHandler done) {
  if (!Attached()) {
    asio::post(socket_.get_executor(), [done = std::move(done)] { done(std::nullopt); });
    return;
  }
  const std::uint64_t id = next_request_++;
  PendingRequest& pending = pending_[id];
  pending.caller_id = request.request_id();
  pending.done = std::move(done);
  pending.deadline =
      std::make_unique<asio::steady_timer>(socket_.get_executor(), options_.node_request_timeout);
  pending.deadline->async_wait([this, self = shared_from_this(), id](const asio::error_code& ec) {
    if (ec) return;
    auto it = pending_.find(id);
    if (it == pending_.end()) return;
    NodeReplyHandler handler = std::move(it->second.done);
    pending_.erase(it);
    spdlog::warn("{}: no reply to node request {} within {} ms", label_, id,
                 options_.node_request_timeout.count());
    handler(std::nullopt);
  });
  request.set_request_id(id);
  filling_.AddNodeRequest(request);
  Queued();
}

void NodeSession::OnNodeReply(const wire::NodeReply& reply) {
  auto it = pending_.find(reply.request_id());
  if (it == pending_.end()) {
    // Answered after its deadline (the caller was already told): nothing to do.
    spdlog::debug("{}: reply to node request {} that is no longer pending", label_, reply.request_id());
    return;
  }
  PendingRequest pending = std::move(it->second);
  pending_.erase(it);
  pending.deadline->cancel();
  stats_->node_replies++;
  wire::NodeReply answer = reply;
  answer.set_request_id(pending.caller_id);
  pending.done(std::move(answer));
}

void NodeSession::FailPendingRequests() {
  auto pending = std::move(pending_);
  pending_.clear();
  for (auto& [id, request] : pending) {
    request.deadline->cancel();
    request.done(std::nullopt);
  }
}

void NodeSession::OnHello(const wire::Hello& hello) {
  if (hello.protocol_version() != wire::kProtocolVersion) {
    Refuse("protocol version " + std::to_string(hello.protocol_version()) +
           " not supported: this broker speaks version " + std::to_string(wire::kProtocolVersion));
    return;
  }
  if (hello.bus().empty() || hello.bus().size() > wire::kMaxNameLength ||
      hello.node_name().size() > wire::kMaxNameLength) {
    Refuse("bus name must be 1.." + std::to_string(wire::kMaxNameLength) + " bytes, node name at most " +
           std::to_string(wire::kMaxNameLength));
    return;
  }
  if (hello.node_id() > 127) {
    Refuse("node_id " + std::to_string(hello.node_id()) + " outside 0..127");
    return;
  }
  if (!ValidBitrate(hello.bitrate())) {
    Refuse("bit rate " + std::to_string(hello.bitrate()) + " outside 10000..1000000 bit/s");
    return;
  }
  if (hello.role() != wire::ROLE_UNSPECIFIED && hello.role() != wire::ROLE_NODE &&
      hello.role() != wire::ROLE_MONITOR) {
    Refuse("unknown role " + std::to_string(hello.role()));
    return;
  }
  const bool monitor = hello.role() == wire::ROLE_MONITOR;
  TimeConductor* conductor = options_.time_conductor;
  if (conductor == nullptr && hello.virtual_time()) {
    Refuse("bus " + hello.bus() +
           " runs in real time; this node was started for virtual time (--time virtual)");
    return;
  }
  if (conductor != nullptr && !hello.virtual_time() && !monitor) {
    Refuse("bus " + hello.bus() +
           " runs in virtual time: a node must run on the broker's clock (canfleet-node --time virtual); "
           "real-time clients may only watch (monitor role); a test's python-can bus joins a fleet its "
           "test drives (Fleet.up(time='virtual'), canfleet up --driven)");
    return;
  }
  if (hello.driven() && (conductor == nullptr || !conductor->Driven() || !hello.clock_id().empty())) {
    Refuse(conductor == nullptr ? "bus " + hello.bus() + " runs in real time: nothing to drive"
           : !hello.clock_id().empty()
               ? std::string("a driven participant names no clock (Hello.clock_id): it is granted no time")
               : "bus " + hello.bus() +
                     " runs in virtual time on its own: a driven participant joins a fleet whose time a test "
                     "runs in steps (canfleet up --driven, as Fleet.up(time='virtual') starts it)");
    return;
  }
  if (conductor != nullptr && !monitor && !hello.driven() && hello.clock_id().empty()) {
    Refuse("a node in virtual time must name its clock (Hello.clock_id)");
    return;
  }
  if (conductor == nullptr || monitor) {
    Accept(hello);
    return;
  }
  // Virtual time: a node joins between rounds, at the bus's time then.
  timer_.cancel();
  conductor->AtBoundary([this, self = shared_from_this(), hello] {
    if (!closed_) Accept(hello);
  });
}

void NodeSession::Accept(const wire::Hello& hello) {
  broker::AttachOptions attach;
  attach.bitrate = hello.bitrate();
  if (hello.role() == wire::ROLE_MONITOR) {
    attach.listen_only = true;
    attach.error_frames = true;
  }
  TimeConductor* conductor = options_.time_conductor;
  std::string name = hello.node_name().empty() ? label_ : hello.node_name();
  try {
    port_ = broker_.Attach(hello.bus(), name, *this, attach);
    bus_ = hello.bus();
    node_name_ = hello.node_name();
    attach_order_ = (*attach_counter_)++;
  } catch (const std::invalid_argument&) {
    Refuse("unknown bus " + hello.bus() + " (this broker has: " + JoinBuses(broker_.Buses()) + ")");
    return;
  }
  timer_.cancel();
  tx_confirmations_ = hello.tx_confirmations();
  const broker::BusStats bus = broker_.Stats(hello.bus(), 0);
  label_ = "session " + label_.substr(label_.find(' ') + 1) + " [" + name + " on " + hello.bus() + ", port " +
           std::to_string(port_) + "]";
  wire::HelloReply reply;
  reply.set_accepted(true);
  reply.set_protocol_version(wire::kProtocolVersion);
  reply.set_bitrate(bus.bitrate);
  reply.set_mode(bus.paced ? wire::BUS_MODE_PACED : wire::BUS_MODE_UNPACED);
  reply.set_port_id(port_);
  reply.set_wall_origin_ns(options_.wall_origin.time_since_epoch().count());
  if (conductor != nullptr) {
    reply.set_virtual_time(true);
    reply.set_time_ns(conductor->Now().time_since_epoch().count());
  }
  filling_.AddHelloReply(reply);
  ScheduleFlush();
  stats_->attached++;
  if (hello.driven()) {
    driven_ = true;
  } else if (conductor != nullptr && hello.role() != wire::ROLE_MONITOR) {
    granted_ = true;
    conductor->Join(*this, hello.clock_id(), hello.clock_attachment(), hello.clock_ports());
  }
  spdlog::info("{}: attached ({}{}{})", label_,
               hello.role() == wire::ROLE_MONITOR ? "monitor"
               : hello.driven()                   ? "driven participant"
                                                  : "node",
               hello.node_id() != 0 ? ", node-ID " + std::to_string(hello.node_id()) : std::string(),
               RateNote(hello.bitrate(), bus.bitrate));
}

void NodeSession::OnBitRate(std::uint32_t bitrate) {
  if (!ValidBitrate(bitrate)) {
    ProtocolError("bit rate " + std::to_string(bitrate) + " outside 10000..1000000 bit/s");
    return;
  }
  broker_.SetPortBitrate(port_, bitrate);
  const std::uint32_t bus = broker_.Stats(bus_, 0).bitrate;
  // A node stating the bus's own rate (commissioned for it) is routine; another rate is news.
  const bool other = bitrate != 0 && bitrate != bus;
  spdlog::log(other ? spdlog::level::info : spdlog::level::debug, "{}: controller now at {} bit/s{}", label_,
              other ? bitrate : bus,
              other ? " (the bus runs at " + std::to_string(bus) + ")" : std::string());
}

void NodeSession::Refuse(const std::string& reason) {
  stats_->refused++;
  wire::HelloReply reply;
  reply.set_accepted(false);
  reply.set_reason(reason);
  reply.set_protocol_version(wire::kProtocolVersion);
  filling_.AddHelloReply(reply);
  Close("refused: " + reason, Farewell::kDrain, spdlog::level::warn);
}

void NodeSession::ProtocolError(const std::string& reason) {
  stats_->protocol_errors++;
  Close("protocol error: " + reason, Farewell::kError, spdlog::level::warn);
}

void NodeSession::Close(const std::string& reason, Farewell farewell, spdlog::level::level_enum level) {
  if (closed_) return;
  const auto self = shared_from_this();  // on_closed_ drops the server's reference
  closed_ = true;
  spdlog::log(level, "{}: closed: {}", label_, reason);
  if (granted_) {
    granted_ = false;
    options_.time_conductor->Leave(*this);
  }
  if (port_ != 0) {
    broker_.Detach(port_);  // no sink call reaches us after this
    port_ = 0;
  }
  timer_.cancel();
  if (on_closed_) on_closed_(this);
  FailPendingRequests();
  if (farewell == Farewell::kNone || !socket_.is_open()) {
    CloseSocket();
    return;
  }
  if (farewell == Farewell::kError) {
    filling_.Clear();
    filling_.AddError(reason);
  }
  Flush();
  if (!write_in_flight_) {
    CloseSocket();
    return;
  }
  timer_.expires_after(options_.close_linger);
  timer_.async_wait([this, self](const asio::error_code& ec) {
    if (!ec) CloseSocket();
  });
}

void NodeSession::CloseSocket() {
  asio::error_code ignored;
  timer_.cancel();
  socket_.shutdown(asio::socket_base::shutdown_both, ignored);
  socket_.close(ignored);
}

void NodeSession::Overflow(std::size_t frames) {
  if (closed_) return;
  if (!slow_.Dropping()) spdlog::warn("{}: not reading; dropping frames for it", label_);
  stats_->backlog_drops += frames;
  if (!slow_.Dropped(frames, SlowReader::Clock::now())) return;
  // Not now: this runs inside the broker's delivery, which must not see its port go.
  asio::post(socket_.get_executor(), [this, self = shared_from_this(), reason = slow_.Reason("frames")] {
    stats_->slow_readers++;
    Close(reason, Farewell::kNone, spdlog::level::warn);
  });
}

void NodeSession::Deliver(std::span<const broker::TimedFrame> frames) {
  if (filling_.size() >= options_.max_backlog_bytes) {
    Overflow(frames.size());
    return;
  }
  if (!acceptance_.All()) {
    // What the node does not listen to does not wake it (its acceptance filter).
    std::size_t accepted = 0;
    Duration reacts_after = Duration::max();
    for (const broker::TimedFrame& f : frames) {
      if (!Accepts(f.frame)) continue;
      filling_.AddFrame(f.frame, f.time);
      reacts_after = std::min(reacts_after, ReactsAfter(f.frame));
      ++accepted;
    }
    stats_->filtered_frames += frames.size() - accepted;
    if (accepted > 0) Queued(reacts_after);
    return;
  }
  filling_.AddFrames(wire::MessageType::kFrames, frames, Stamped);
  Queued();
}

void NodeSession::DeliverShared(const broker::SharedRound& round, std::span<const broker::FrameRun> runs) {
  std::size_t frames = 0;
  for (const broker::FrameRun& run : runs)
    frames += run.size();
  if (filling_.size() >= options_.max_backlog_bytes) {
    Overflow(frames);
    return;
  }
  const std::uint8_t* records = transport::SharedRecords(round);
  Duration reacts_after = Duration::zero();  // every frame: it may answer at once
  if (!acceptance_.All()) {
    // What the node does not listen to does not wake it (its acceptance filter). When it takes
    // every frame of the round, they go out as without a filter (gathered, below).
    const std::span<const broker::TimedFrame> all = round.Frames();
    std::size_t accepted = 0;
    reacts_after = Duration::max();
    for (const broker::FrameRun& run : runs) {
      for (std::uint32_t i = run.begin; i < run.end; ++i) {
        if (!Accepts(all[i].frame)) continue;
        ++accepted;
        reacts_after = std::min(reacts_after, ReactsAfter(all[i].frame));
      }
    }
    stats_->filtered_frames += frames - accepted;
    if (accepted == 0) return;
    if (accepted < frames) {
      for (const broker::FrameRun& run : runs)
        for (std::uint32_t i = run.begin; i < run.end; ++i)
          if (Accepts(all[i].frame))
            filling_.AddRecords(wire::MessageType::kFrames, records + std::size_t{i} * wire::kFrameRecordSize,
                                1);
      Queued(reacts_after);
      return;
    }
  }
  // In virtual time the grant that follows sends the frames: frames and grant in one write.
  if (!granted_ && !write_in_flight_ && socket_.is_open() && runs.size() <= kMaxGatherRuns &&
      frames <= wire::kMaxFramesPerMessage) {
    if (driven_) options_.time_conductor->Wake();  // before the write, which may close the session
    WriteGathered(records, runs, frames);
    return;
  }
  filling_.ExpectFrames(wire::MessageType::kFrames, frames);
  for (const broker::FrameRun& run : runs)
    filling_.AddRecords(wire::MessageType::kFrames, records + std::size_t{run.begin} * wire::kFrameRecordSize,
                        run.size());
  Queued(reacts_after);
}

void NodeSession::WriteGathered(const std::uint8_t* records, std::span<const broker::FrameRun> runs,
                                std::size_t frames) {
  // What is queued for this port goes first (a controller event earlier in the round, a pong),
  // then one Frames message: our header, then the runs straight from the round's encoding. The
  // kernel copies them into the socket; nothing is copied on the way (issue 4: a frame to 31
  // receivers was copied 31 times into 31 session buffers, a quarter of the broker's CPU).
  std::array<iovec, kMaxGatherRuns + 2> buffers;
  std::size_t count = 0;
  const std::span<const std::uint8_t> queued = filling_.Bytes();
  if (!queued.empty()) buffers[count++] = {const_cast<std::uint8_t*>(queued.data()), queued.size()};
  buffers[count++] = {header_.data(),
                      wire::WriteBatchHeader(wire::MessageType::kFrames, frames, header_.data())};
  for (const broker::FrameRun& run : runs)
    buffers[count++] = {const_cast<std::uint8_t*>(records + std::size_t{run.begin} * wire::kFrameRecordSize),
                        std::size_t{run.size()} * wire::kFrameRecordSize};
  stats_->gathered_writes++;
  SendNow({buffers.data(), count});  // may close the session: nothing after it
}

void NodeSession::ControllerChanged(const ControllerEvent& event) {
  filling_.AddControllerEvent(event);
  Queued();
}

void NodeSession::TxConfirmed(std::span<const broker::TimedFrame> frames) {
  if (!tx_confirmations_) return;
  filling_.AddFrames(wire::MessageType::kTxConfirm, frames, Stamped);
  Queued();
}

void NodeSession::SendGrant(TimePoint now, TimePoint until, std::span<const std::uint64_t> attachments) {
  filling_.AddTimeGrant(now.time_since_epoch().count(), until.time_since_epoch().count(), attachments);
  ScheduleFlush();
}

void NodeSession::Evict(const std::string& reason) {
  Close(reason, Farewell::kError, spdlog::level::warn);
}

void NodeSession::ScheduleFlush() {
  if (flush_posted_ || write_in_flight_) return;
  flush_posted_ = true;
  asio::post(socket_.get_executor(), [this, self = shared_from_this()] {
    flush_posted_ = false;
    Flush();
  });
}

void NodeSession::Flush() {
  if (write_in_flight_ || filling_.empty() || !socket_.is_open()) return;
  const std::span<const std::uint8_t> bytes = filling_.Bytes();
  const iovec buffer{const_cast<std::uint8_t*>(bytes.data()), bytes.size()};
  SendNow({&buffer, 1});
}

void NodeSession::SendNow(std::span<const iovec> message) {
  std::error_code ec;
  const std::size_t sent = wire::SendNow(socket_.native_handle(), message, ec);
  stats_->writes++;
  if (ec && !wire::WouldBlock(ec)) {
    if (closed_)
      CloseSocket();
    else
      Close(ec.message(), Farewell::kNone, spdlog::level::info);
    return;
  }
  if (sent == wire::TotalSize(message)) {
    filling_.Clear();
    Written();
    return;
  }
  // The socket took only part: the rest is this session's to keep until it can be written.
  stats_->partial_writes++;
  writing_.Clear();
  wire::AppendUnsent(message, sent, [this](const std::uint8_t* bytes, std::size_t size) {
    writing_.AddEncoded(bytes, size);
  });
  filling_.Clear();
  WriteRest();
}

void NodeSession::WriteRest() {
  // The slow path: the socket is full (a peer reading slower than the bus delivers). What is
  // delivered meanwhile collects in filling_, up to BrokerServerOptions::max_backlog_bytes.
  write_in_flight_ = true;
  asio::async_write(socket_, Buffer(writing_.Bytes()),
                    [this, self = shared_from_this()](const asio::error_code& ec, std::size_t) {
                      write_in_flight_ = false;
                      writing_.Clear();
                      if (ec) {
                        if (closed_)
                          CloseSocket();
                        else
                          Close(ec.message(), Farewell::kNone, spdlog::level::info);
                        return;
                      }
                      if (!filling_.empty()) {
                        Flush();
                        return;
                      }
                      Written();
                    });
}

void NodeSession::Written() {
  if (closed_) {
    CloseSocket();
    return;
  }
  if (const auto lost = slow_.CaughtUp(); lost != 0)
    spdlog::warn("{}: reading again; {} frames were dropped", label_, lost);
}

}  // namespace canfleet::transport::detail
