#include "bus/broker_client/broker_client_port.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <asio/connect.hpp>
#include <asio/generic/stream_protocol.hpp>
#include <asio/ip/tcp.hpp>
#include <asio/local/stream_protocol.hpp>
#include <asio/post.hpp>
#include <asio/steady_timer.hpp>
#include <asio/write.hpp>
#include <span>
#include <stdexcept>

#include "bus/physics/wire_model.hpp"
#include "bus/wire/auth_token.hpp"
#include "bus/wire/endpoint.hpp"
#include "bus/wire/message_writer.hpp"
#include "bus/wire/socket_io.hpp"
#include "bus/wire/stream_decoder.hpp"

namespace canfleet {

namespace {

/// Bytes asked of the socket per read: many batches at once under load.
constexpr std::size_t kReadChunk = 64 * 1024;

asio::const_buffer Buffer(std::span<const std::uint8_t> s) {
  return {s.data(), s.size()};
}

long long Ms(std::chrono::milliseconds d) {
  return static_cast<long long>(d.count());
}

}  // namespace

/// The connection state machine. Owned through a shared_ptr so that every pending Asio handler
/// keeps it alive ([this, self] captures, style.md "Asio lifetimes"); the port only points to it
/// and detaches itself (owner_ = nullptr) when destroyed. Each connection attempt has a
/// generation number: completions of an older socket are ignored.
class BrokerClientPort::Link : public std::enable_shared_from_this<Link>, public GrantedPort {
 public:
  Link(asio::io_context& io, BrokerClientPort& owner, BrokerClientOptions options)
      : io_(io),
        owner_(&owner),
        options_(std::move(options)),
        endpoint_(wire::Endpoint::Parse(options_.endpoint)),
        socket_(io),
        resolver_(io),
        timer_(io),
        backoff_(options_.initial_backoff) {}

  void Start() {
    asio::post(io_, [this, self = shared_from_this()] { Connect(); });
  }

  void Shutdown() {
    if ((phase_ == Phase::kConnected || phase_ == Phase::kHandshake) && options_.virtual_time)
      options_.virtual_time->Disconnected(options_.virtual_time_index);
    owner_ = nullptr;
    phase_ = Phase::kStopped;
    ++generation_;
    CloseSocket();
    timer_.cancel();
    resolver_.cancel();
  }

  bool Send(const CanFrame& frame) {
    if (phase_ != Phase::kConnected || options_.monitor || !frame.valid() || frame.error() ||
        state_ == ControllerState::kBusOff || filling_.frame_count() >= options_.transmit_queue_frames) {
      ++stats_.tx_refused;
      return false;
    }
    if (options_.virtual_time) CheckConfinement(frame);
    // In virtual time a frame carries the time it was sent: the broker puts it on the bus then.
    filling_.AddFrame(frame, options_.virtual_time
                                 ? options_.virtual_time->scheduler().Now().time_since_epoch()
                                 : BusTime::zero());
    ++stats_.tx_frames;
    ScheduleFlush();
    return true;
  }

  ControllerState State() const { return state_; }

  void AcceptanceMayHaveChanged() {
    if (!options_.virtual_time && phase_ == Phase::kConnected) ScheduleFlush();  // Flush refreshes it
  }

  /// A timer confined to one identifier (Timer::Confine) promised to send only that: another frame
  /// from it breaks what per-node lookahead grants others on (issue 34). Counted, and said once.
  void CheckConfinement(const CanFrame& frame) {
    const std::uint32_t key = options_.virtual_time->scheduler().RunningConfinement();
    if (key == Timer::kUnconfined || (!frame.extended() && frame.id == (key & ~Timer::kHeartbeat))) return;
    ++stats_.confinement_breaches;
    if (breach_logged_) return;
    breach_logged_ = true;
    spdlog::error(
        "virtual time: a timer confined to identifier {:03X}h sent {:X}h: other nodes may have been granted "
        "past "
        "it (a bug of the node; grant_horizon.hpp)",
        key, frame.id);
  }

  void SetBitRate(std::uint32_t bitrate) {
    if (bitrate == options_.bitrate) return;
    options_.bitrate = bitrate;
    error_frame_logged_ = false;
    if (phase_ == Phase::kConnected || phase_ == Phase::kHandshake) {
      // In the handshake the Hello already left with the old rate: this follows it.
      const bool other = bitrate != 0 && bitrate != session_.bitrate;
      spdlog::log(other || phase_ != Phase::kConnected ? spdlog::level::info : spdlog::level::debug,
                  "bus {}: controller now at {}", options_.bus, RateText(bitrate));
      filling_.AddBitRate(bitrate);
      ScheduleFlush();
    } else {
      spdlog::info("bus {}: controller at {} from the next connection", options_.bus, RateText(bitrate));
    }
  }
  std::uint32_t BitRate() const { return options_.bitrate; }

  bool Connected() const { return phase_ == Phase::kConnected; }
  std::optional<BrokerSession> Session() const {
    return Connected() ? std::optional(session_) : std::nullopt;
  }
  const BrokerClientStats& Stats() const { return stats_; }

  ConnectionHandler on_connection;
  TxConfirmHandler on_tx_confirmed;
  NodeRequestHandler on_node_request;
  AcceptanceProvider acceptance;
  PassiveProvider passive;

 private:
  enum class Phase : std::uint8_t { kIdle, kConnecting, kHandshake, kConnected, kWaiting, kStopped };

  void Connect() {
    if (phase_ == Phase::kStopped) return;
    phase_ = Phase::kConnecting;
    const std::uint64_t gen = ++generation_;
    spdlog::debug("connecting to broker at {}", endpoint_.ToString());
    timer_.expires_after(options_.handshake_timeout);
    timer_.async_wait([this, self = shared_from_this(), gen](const asio::error_code& ec) {
      if (ec || gen != generation_) return;
      Fail("no HelloReply within " + std::to_string(Ms(options_.handshake_timeout)) + " ms");
    });
    if (endpoint_.kind == wire::Endpoint::Kind::kUnix) {
      socket_.async_connect(asio::local::stream_protocol::endpoint(endpoint_.path),
                            [this, self = shared_from_this(), gen](const asio::error_code& ec) {
                              if (gen == generation_) OnConnected(ec);
                            });
      return;
    }
    resolver_.async_resolve(
        endpoint_.host, std::to_string(endpoint_.port),
        [this, self = shared_from_this(), gen](const asio::error_code& ec,
                                               const asio::ip::tcp::resolver::results_type& results) {
          if (gen != generation_) return;
          if (ec || results.empty()) {
            Fail("cannot resolve " + endpoint_.host + ": " + (ec ? ec.message() : "no address"));
            return;
          }
          const asio::generic::stream_protocol::endpoint target(results.begin()->endpoint());
          socket_.async_connect(target, [this, self, gen](const asio::error_code& connect_ec) {
            if (gen == generation_) OnConnected(connect_ec);
          });
        });
  }

  void OnConnected(const asio::error_code& ec) {
    if (ec) {
      Fail(ec.message());
      return;
    }
    if (endpoint_.kind == wire::Endpoint::Kind::kTcp) {
      asio::error_code ignored;
      socket_.set_option(asio::ip::tcp::no_delay(true), ignored);  // a batch is complete when written
    }
    phase_ = Phase::kHandshake;
    if (endpoint_.kind == wire::Endpoint::Kind::kTcp && !options_.token.empty()) {
      const std::string preamble = wire::EncodeAuthPreamble(options_.token);
      filling_.AddEncoded(reinterpret_cast<const std::uint8_t*>(preamble.data()), preamble.size());
    }
    wire::Hello hello = wire::MakeHello(options_.bus, options_.node_name, options_.node_id,
                                        options_.monitor ? wire::ROLE_MONITOR : wire::ROLE_NODE);
    hello.set_tx_confirmations(options_.tx_confirmations);
    hello.set_bitrate(options_.bitrate);
    if (options_.virtual_time) {
      hello.set_virtual_time(true);
      hello.set_clock_id(options_.virtual_time->clock_id());
      hello.set_clock_ports(static_cast<std::uint32_t>(options_.virtual_time->port_count()));
      // From here the broker may join this connection and name it in a grant another port reads
      // first: the process's other ports wait for it (VirtualTimeClient::RunIfAllGranted).
      hello.set_clock_attachment(options_.virtual_time->Attaching(options_.virtual_time_index));
    }
    filling_.AddHello(hello);
    const std::uint64_t gen = generation_;
    Flush();
    if (gen != generation_) return;  // the write failed: Fail() has scheduled the next attempt
    Read();
  }

  /// One read, then (once the socket is drained) a wait for readiness (bus/wire/socket_io.hpp):
  /// no recv is made only to learn that nothing is left. The wait is armed in the handler whose
  /// read found the socket drained, so data arriving later always finds it.
  void Read() {
    const std::uint64_t gen = generation_;
    const std::span<std::uint8_t> space = decoder_.WritableSpace(kReadChunk);
    std::error_code ec;
    const std::size_t n = wire::ReceiveNow(socket_.native_handle(), space, ec);
    ++stats_.reads;
    if (wire::WouldBlock(ec)) {
      ++stats_.empty_reads;
      WaitReadable();
      return;
    }
    if (ec) {
      Fail(ec == wire::EndOfStream() ? "the broker closed the connection" : ec.message());
      return;
    }
    decoder_.Commit(n);
    reading_ = true;
    for (;;) {
      const auto result = decoder_.Next(message_);
      if (result == wire::StreamDecoder::Result::kNeedMore) break;
      if (result == wire::StreamDecoder::Result::kError) {
        reading_ = false;
        ProtocolError("malformed data from the broker: " + decoder_.Error());
        return;
      }
      Handle(message_);
      if (gen != generation_) return;  // the handler failed or destroyed the port
    }
    reading_ = false;
    Flush();
    if (gen != generation_) return;  // the write failed
    if (n < space.size()) {
      WaitReadable();
      return;
    }
    // A full chunk: more may be waiting; read it after the handlers already queued (timers).
    asio::post(io_, [this, self = shared_from_this(), gen] {
      if (gen == generation_) Read();
    });
  }

  void WaitReadable() {
    const std::uint64_t gen = generation_;
    socket_.async_wait(asio::socket_base::wait_read,
                       [this, self = shared_from_this(), gen](const asio::error_code& ec) {
                         if (gen != generation_) return;
                         if (ec) {
                           Fail(ec.message());
                           return;
                         }
                         Read();
                       });
  }

  void Handle(const wire::Message& m) {
    if (phase_ == Phase::kHandshake) {
      if (m.type == wire::MessageType::kHelloReply) {
        OnHelloReply(m.envelope.hello_reply());
      } else if (m.type == wire::MessageType::kError) {
        Fail("the broker closed the connection: " + m.envelope.error().reason());
      } else {
        ProtocolError(std::string("unexpected ") + wire::ToString(m.type) + " before HelloReply");
      }
      return;
    }
    if (options_.virtual_time && Hold(m)) return;
    switch (m.type) {
      case wire::MessageType::kFrames:
        stats_.rx_frames += m.frames.size();
        for (std::size_t i = 0; i < m.frames.size(); ++i) {
          const wire::StampedFrame f = m.frames[i];
          if (f.frame.error()) OnErrorFrame(f.frame);
          owner_->Deliver(f.frame, f.time);
          if (owner_ == nullptr) return;
        }
        return;
      case wire::MessageType::kTxConfirm:
        for (std::size_t i = 0; i < m.frames.size() && on_tx_confirmed; ++i) {
          const wire::StampedFrame f = m.frames[i];
          on_tx_confirmed(f.frame, f.time);
          if (owner_ == nullptr) return;
        }
        return;
      case wire::MessageType::kControllerEvent:
        state_ = m.controller.state;
        owner_->NotifyState(m.controller);
        return;
      case wire::MessageType::kPing:
        filling_.AddPong(m.envelope.ping().nonce());
        ScheduleFlush();
        return;
      case wire::MessageType::kPong:
        return;
      case wire::MessageType::kError:
        Fail("the broker closed the connection: " + m.envelope.error().reason());
        return;
      case wire::MessageType::kNodeRequest:
        OnNodeRequest(m.envelope.node_request());
        return;
      case wire::MessageType::kTimeGrant: {
        if (!options_.virtual_time) {
          ProtocolError("TimeGrant on a connection in real time");
          return;
        }
        const wire::TimeGrant& grant = m.envelope.time_grant();
        options_.virtual_time->Granted(options_.virtual_time_index, TimePoint(Duration(grant.now_ns())),
                                       TimePoint(Duration(grant.until_ns())),
                                       std::span(grant.attachments().data(), grant.attachments().size()));
        return;
      }
      case wire::MessageType::kHello:
      case wire::MessageType::kHelloReply:
      case wire::MessageType::kNodeReply:
      case wire::MessageType::kBitRate:
      case wire::MessageType::kTimeReached:
      case wire::MessageType::kAcceptance:
        ProtocolError(std::string("unexpected ") + wire::ToString(m.type) + " from the broker");
        return;
    }
  }

  /// Virtual time: what happens at the next grant's time is held until that grant. True when `m`
  /// was held.
  bool Hold(const wire::Message& m) {
    switch (m.type) {
      case wire::MessageType::kFrames:
      case wire::MessageType::kTxConfirm:
        for (std::size_t i = 0; i < m.frames.size(); ++i)
          held_.push_back({m.type, m.frames[i], {}, 0});
        return true;
      case wire::MessageType::kControllerEvent:
        held_.push_back({m.type, {}, m.controller, 0});
        return true;
      case wire::MessageType::kNodeRequest:
        held_requests_.push_back(m.envelope.node_request());
        held_.push_back({m.type, {}, {}, held_requests_.size() - 1});
        return true;
      default:
        return false;
    }
  }

  void ApplyHeld() override {
    const std::uint64_t gen = generation_;
    // Swapped out: applying may hold nothing new (no reads happen meanwhile), but a handler may
    // destroy the port.
    std::vector<Held> items;
    items.swap(held_);
    std::vector<wire::NodeRequest> requests;
    requests.swap(held_requests_);
    for (const Held& item : items) {
      if (gen != generation_ || owner_ == nullptr) return;
      switch (item.type) {
        case wire::MessageType::kFrames:
          ++stats_.rx_frames;
          if (item.frame.frame.error()) OnErrorFrame(item.frame.frame);
          owner_->Deliver(item.frame.frame, item.frame.time);
          break;
        case wire::MessageType::kTxConfirm:
          if (on_tx_confirmed) on_tx_confirmed(item.frame.frame, item.frame.time);
          break;
        case wire::MessageType::kControllerEvent:
          state_ = item.controller.state;
          owner_->NotifyState(item.controller);
          break;
        case wire::MessageType::kNodeRequest:
          OnNodeRequest(requests[item.request]);
          break;
        default:
          break;
      }
    }
    if (gen != generation_) return;
    items.clear();
    requests.clear();
    if (held_.empty()) held_.swap(items);  // keep the storage
    if (held_requests_.empty()) held_requests_.swap(requests);
  }

  /// The filter as the node's configuration makes it now, with its passive heartbeats (virtual
  /// time only: per-node lookahead is all they serve).
  struct Filter {
    std::optional<std::vector<std::uint32_t>> ids;
    std::vector<std::pair<std::uint32_t, std::int64_t>> passive;
    bool operator==(const Filter&) const = default;
  };
  Filter CurrentFilter() const {
    Filter f{acceptance(), {}};
    if (passive && options_.virtual_time && f.ids)
      for (const auto& [id, delay] : passive())
        f.passive.emplace_back(id, delay.count());
    return f;
  }
  static void AddFilter(wire::MessageWriter& out, const Filter& f) { out.AddAcceptance(f.ids, f.passive); }

  bool AcceptanceChanged() override {
    if (!acceptance || phase_ != Phase::kConnected) return false;
    return acceptance_sent_ && CurrentFilter() != last_acceptance_;
  }

  void Reached(TimePoint time, std::optional<TimePoint> next_deadline, const TimerOutlook& outlook) override {
    if (phase_ != Phase::kConnected) return;
    if (acceptance) {
      Filter filter = CurrentFilter();
      if (!acceptance_sent_ || filter != last_acceptance_) {
        AddFilter(filling_, filter);
        last_acceptance_ = std::move(filter);
        acceptance_sent_ = true;
      }
    }
    // What its timers may send: its heartbeat and TPDO timers are confined to their identifiers;
    // a key above 0x7FF (none on a node) would not be an identifier, so it counts as anything.
    reached_outlook_.any_ns.reset();
    reached_outlook_.confined.clear();
    if (outlook.unconfined) reached_outlook_.any_ns = outlook.unconfined->time_since_epoch().count();
    for (const auto& [key, deadline] : outlook.confined) {
      const std::int64_t ns = deadline.time_since_epoch().count();
      const std::uint32_t id = key & ~Timer::kHeartbeat;
      if (id <= 0x7FF)
        reached_outlook_.confined.push_back({id, ns, (key & Timer::kHeartbeat) != 0});
      else
        reached_outlook_.any_ns = std::min(reached_outlook_.any_ns.value_or(ns), ns);
    }
    filling_.AddTimeReached(
        time.time_since_epoch().count(),
        next_deadline ? std::optional(next_deadline->time_since_epoch().count()) : std::nullopt,
        &reached_outlook_);
    ScheduleFlush();
  }

  /// Real time: before each write, the filter as the node's configuration now makes it; a change
  /// goes first in the write, ahead of the frames that answer what changed it (an SDO download's
  /// response, a boot-up after a reset), so the broker applies it before anyone hears the answer.
  /// A configuration changes only with a command the node answers (CanopenStack::ListenedIds), so
  /// only frames already in flight when the command came can miss a new filter, as on a real
  /// controller whose filter is being rewritten.
  void RefreshAcceptance() {
    if (!acceptance) return;
    Filter ids = CurrentFilter();
    if (acceptance_sent_ && ids == last_acceptance_) return;
    if (filling_.empty()) {
      AddFilter(filling_, ids);
    } else {
      acceptance_first_.Clear();
      AddFilter(acceptance_first_, ids);
      const std::span<const std::uint8_t> rest = filling_.Bytes();
      acceptance_first_.AddEncoded(rest.data(), rest.size());
      filling_.Swap(acceptance_first_);
      acceptance_first_.Clear();
    }
    last_acceptance_ = std::move(ids);
    acceptance_sent_ = true;
  }

  /// Counts error frames; the first one after a connection or a rate change is logged, with the
  /// rates when they differ (the usual cause: the controller is at another rate than the bus).
  void OnErrorFrame(const CanFrame& frame) {
    ++stats_.rx_error_frames;
    if (error_frame_logged_) return;
    error_frame_logged_ = true;
    const std::uint32_t own = options_.bitrate != 0 ? options_.bitrate : session_.bitrate;
    if (own != session_.bitrate) {
      spdlog::warn("bus {}: error frames (first: {}): the controller runs at {} bit/s, the bus at {} bit/s",
                   options_.bus, ToCandump(frame), own, session_.bitrate);
    } else {
      spdlog::warn("bus {}: error frames (first: {})", options_.bus, ToCandump(frame));
    }
  }

  static std::string RateText(std::uint32_t bitrate) {
    return bitrate != 0 ? std::to_string(bitrate) + " bit/s" : std::string("the bus's bit rate");
  }

  void OnNodeRequest(const wire::NodeRequest& request) {
    const std::uint64_t id = request.request_id();
    wire::NodeReply reply;
    if (on_node_request) {
      const std::uint64_t gen = generation_;
      reply = on_node_request(request);
      if (gen != generation_ || owner_ == nullptr) return;  // the handler destroyed the port
    } else {
      reply.set_error((options_.node_name.empty() ? std::string("this client") : options_.node_name) +
                      " serves no node requests");
    }
    reply.set_request_id(id);
    filling_.AddNodeReply(reply);
    ScheduleFlush();
  }

  void OnHelloReply(const wire::HelloReply& reply) {
    if (!reply.accepted()) {
      spdlog::error("broker at {} refused bus {}: {}", endpoint_.ToString(), options_.bus, reply.reason());
      const std::string detail = "refused: " + reply.reason();
      Fail(detail);
      // Unlike an absent broker, a refusal may never go away (protocol version, unknown bus): the
      // node process is told, so it can give up. The port keeps retrying unless destroyed.
      if (on_connection) on_connection(false, detail);
      return;
    }
    if (reply.virtual_time() != (options_.virtual_time != nullptr)) {
      const std::string detail = std::string("refused: the bus runs in ") +
                                 (reply.virtual_time() ? "virtual" : "real") + " time, this node in " +
                                 (options_.virtual_time ? "virtual" : "real") + " time";
      spdlog::error("broker at {} bus {}: {}", endpoint_.ToString(), options_.bus, detail);
      Fail(detail);
      if (on_connection) on_connection(false, detail);
      return;
    }
    timer_.cancel();
    phase_ = Phase::kConnected;
    backoff_ = options_.initial_backoff;
    session_ = {reply.port_id(), reply.bitrate(), reply.mode() != wire::BUS_MODE_UNPACED,
                reply.virtual_time()};
    held_.clear();
    held_requests_.clear();
    acceptance_sent_ = false;  // a new attachment knows no filter
    if (options_.virtual_time) {
      const std::uint64_t gen_before = generation_;
      options_.virtual_time->Connected(options_.virtual_time_index, *this,
                                       TimePoint(Duration(reply.time_ns())));
      if (gen_before != generation_) return;
    }
    ++stats_.connects;
    error_frame_logged_ = false;
    const bool other_rate = options_.bitrate != 0 && options_.bitrate != session_.bitrate;
    const std::string detail =
        endpoint_.ToString() + " bus " + options_.bus + " (" + std::to_string(session_.bitrate) + " bit/s, " +
        (session_.paced ? "paced" : "unpaced") + (session_.virtual_time ? ", virtual time" : "") +
        "), port " + std::to_string(session_.port_id) +
        (other_rate ? ", controller at " + std::to_string(options_.bitrate) + " bit/s" : std::string());
    spdlog::info("connected to broker at {}", detail);
    const std::uint64_t gen = generation_;
    if (state_ != ControllerState::kErrorActive) {
      // A new attachment is a new controller (error-active, counters 0).
      state_ = ControllerState::kErrorActive;
      owner_->NotifyState({ControllerState::kErrorActive, 0, 0});
      if (gen != generation_) return;
    }
    if (on_connection) on_connection(true, detail);
  }

  /// The peer broke the protocol: say why (best effort), then drop the connection.
  void ProtocolError(const std::string& reason) {
    spdlog::error("protocol error from broker at {}: {}", endpoint_.ToString(), reason);
    if (socket_.is_open()) {
      // Written synchronously past any queued data is not possible mid-write; only when idle.
      if (!write_in_flight_) {
        wire::MessageWriter error;
        error.AddError(reason);
        asio::error_code ignored;
        socket_.non_blocking(true, ignored);
        socket_.write_some(Buffer(error.Bytes()), ignored);
      }
    }
    Fail(reason);
  }

  void Fail(const std::string& reason) {
    if (phase_ == Phase::kStopped) return;
    const bool was_connected = phase_ == Phase::kConnected;
    // An attempt that sent its Hello may be named by a grant another port holds: no longer wait.
    if ((was_connected || phase_ == Phase::kHandshake) && options_.virtual_time)
      options_.virtual_time->Disconnected(options_.virtual_time_index);
    ++generation_;
    CloseSocket();
    timer_.cancel();
    resolver_.cancel();
    phase_ = Phase::kWaiting;
    const auto delay = backoff_;
    backoff_ = std::min(backoff_ * 2, options_.max_backoff);
    if (was_connected) {
      ++stats_.disconnects;
      spdlog::warn("broker connection lost: {}; reconnecting in {} ms", reason, Ms(delay));
    } else {
      ++stats_.failed_attempts;
      spdlog::warn("cannot attach to broker at {}: {}; retrying in {} ms", endpoint_.ToString(), reason,
                   Ms(delay));
    }
    const std::uint64_t gen = generation_;
    timer_.expires_after(delay);
    timer_.async_wait([this, self = shared_from_this(), gen](const asio::error_code& ec) {
      if (!ec && gen == generation_) Connect();
    });
    if (was_connected && on_connection) on_connection(false, reason);
  }

  void CloseSocket() {
    asio::error_code ignored;
    socket_.shutdown(asio::socket_base::shutdown_both, ignored);
    socket_.close(ignored);
    // Pending operations were cancelled with the socket: the buffers are free again.
    write_in_flight_ = false;
    reading_ = false;
    filling_.Clear();
    writing_.Clear();
    decoder_ = wire::StreamDecoder();
  }

  void ScheduleFlush() {
    // Inside a read handler (frames being delivered), the read flushes when its batch is done:
    // what the node answers to one batch leaves in one write, without a posted handler (which
    // would also cost the event loop an extra epoll_wait before running it).
    if (flush_posted_ || write_in_flight_ || reading_) return;
    flush_posted_ = true;
    asio::post(io_, [this, self = shared_from_this()] {
      flush_posted_ = false;
      Flush();
    });
  }

  /// Writes everything appended so far in one write, straight away; what the socket does not take
  /// is written asynchronously, and what is appended meanwhile waits for it.
  void Flush() {
    if (write_in_flight_ || !socket_.is_open()) return;
    if (!options_.virtual_time && phase_ == Phase::kConnected) RefreshAcceptance();
    if (filling_.empty()) return;
    const std::span<const std::uint8_t> bytes = filling_.Bytes();
    const iovec buffer{const_cast<std::uint8_t*>(bytes.data()), bytes.size()};
    std::error_code ec;
    const std::size_t sent = wire::SendNow(socket_.native_handle(), {&buffer, 1}, ec);
    ++stats_.writes;
    if (ec && !wire::WouldBlock(ec)) {
      Fail(ec.message());
      return;
    }
    if (sent == bytes.size()) {
      filling_.Clear();
      return;
    }
    ++stats_.partial_writes;
    writing_.Clear();
    writing_.AddEncoded(bytes.data() + sent, bytes.size() - sent);
    filling_.Clear();
    write_in_flight_ = true;
    const std::uint64_t gen = generation_;
    asio::async_write(socket_, Buffer(writing_.Bytes()),
                      [this, self = shared_from_this(), gen](const asio::error_code& write_ec, std::size_t) {
                        if (gen != generation_) return;
                        write_in_flight_ = false;
                        writing_.Clear();
                        if (write_ec) {
                          Fail(write_ec.message());
                          return;
                        }
                        Flush();
                      });
  }

  asio::io_context& io_;
  BrokerClientPort* owner_;
  BrokerClientOptions options_;
  wire::Endpoint endpoint_;
  asio::generic::stream_protocol::socket socket_;
  asio::ip::tcp::resolver resolver_;
  asio::steady_timer timer_;  ///< handshake deadline, then reconnection delay
  std::chrono::milliseconds backoff_;
  Phase phase_ = Phase::kIdle;
  std::uint64_t generation_ = 0;

  wire::StreamDecoder decoder_;
  wire::Message message_;
  wire::MessageWriter filling_;           ///< appended to by Send and replies
  wire::MessageWriter writing_;           ///< the unwritten rest of a write the socket took only in part
  wire::MessageWriter acceptance_first_;  ///< real time: a new filter ahead of filling_'s messages
  bool write_in_flight_ = false;
  bool flush_posted_ = false;
  bool reading_ = false;  ///< delivering the messages of one read; it flushes when done

  ControllerState state_ = ControllerState::kErrorActive;
  bool error_frame_logged_ = false;
  /// Virtual time: what the broker sent since its last grant.
  struct Held {
    wire::MessageType type;
    wire::StampedFrame frame;
    canfleet::ControllerEvent controller;
    std::size_t request = 0;  ///< into held_requests_
  };
  std::vector<Held> held_;
  std::vector<wire::NodeRequest> held_requests_;
  /// The acceptance filter last sent on this connection.
  Filter last_acceptance_;
  bool acceptance_sent_ = false;
  bool breach_logged_ = false;
  wire::MessageWriter::ReachedOutlook reached_outlook_;  ///< reused
  BrokerSession session_;
  BrokerClientStats stats_;
};

BrokerClientPort::BrokerClientPort(asio::io_context& io, BrokerClientOptions options)
    : link_(std::make_shared<Link>(io, *this, std::move(options))) {
  link_->Start();
}

BrokerClientPort::~BrokerClientPort() {
  link_->Shutdown();
}

bool BrokerClientPort::Send(const CanFrame& frame) {
  return link_->Send(frame);
}

ControllerState BrokerClientPort::State() const {
  return link_->State();
}

bool BrokerClientPort::SetBitRate(std::uint32_t bit_per_s) {
  if (bit_per_s != 0 && (bit_per_s < kMinBitrate || bit_per_s > kMaxBitrate)) return false;
  link_->SetBitRate(bit_per_s);
  return true;
}

void BrokerClientPort::OnPassive(PassiveProvider provider) {
  link_->passive = std::move(provider);
}

void BrokerClientPort::AcceptanceMayHaveChanged() {
  link_->AcceptanceMayHaveChanged();
}

std::uint32_t BrokerClientPort::BitRate() const {
  return link_->BitRate();
}

bool BrokerClientPort::Connected() const {
  return link_->Connected();
}

std::optional<BrokerSession> BrokerClientPort::Session() const {
  return link_->Session();
}

void BrokerClientPort::OnConnection(ConnectionHandler handler) {
  link_->on_connection = std::move(handler);
}

void BrokerClientPort::OnTxConfirmed(TxConfirmHandler handler) {
  link_->on_tx_confirmed = std::move(handler);
}

void BrokerClientPort::OnNodeRequest(NodeRequestHandler handler) {
  link_->on_node_request = std::move(handler);
}

void BrokerClientPort::OnAcceptance(AcceptanceProvider provider) {
  link_->acceptance = std::move(provider);
}

const BrokerClientStats& BrokerClientPort::Stats() const {
  return link_->Stats();
}

}  // namespace canfleet
