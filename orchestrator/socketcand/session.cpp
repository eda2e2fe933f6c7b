#include "orchestrator/socketcand/session.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <asio/error.hpp>
#include <asio/post.hpp>
#include <asio/write.hpp>
#include <stdexcept>

namespace canfleet::socketcand::detail {
namespace {

/// Writes go out in pieces of this size, a multiple of kAlignedRecordSize: a write never ends
/// inside an aligned record unless the kernel's send buffer is full.
constexpr std::size_t kWriteChunk = 16 * 1024;
static_assert(kWriteChunk % kAlignedRecordSize == 0);

/// While paused, a session still reads this much ahead, so that it notices a client that closes
/// its connection (see StartDrain).
constexpr std::size_t kPausedReadAhead = 64 * 1024;

/// Protocol errors logged per session before it goes quiet (a broken client can send millions).
constexpr std::uint64_t kLoggedProtocolErrors = 10;

std::string Printable(std::string_view text) {
  std::string out;
  for (char c : text.substr(0, 80))
    out += (c >= 0x20 && c < 0x7F) ? c : '?';
  if (text.size() > 80) out += "...";
  return out;
}

}  // namespace

bool Context::Serves(std::string_view bus) const {
  return std::find(buses.begin(), buses.end(), bus) != buses.end();
}

Session::Session(std::shared_ptr<Context> context, asio::generic::stream_protocol::socket socket,
                 std::string_view listener_bus, std::string peer)
    : ctx_(std::move(context)),
      socket_(std::move(socket)),
      peer_(std::move(peer)),
      name_("socketcand " + std::string(listener_bus) + " " + peer_),
      slow_(ctx_->options.slow_client_limit) {
  drain_timer_.emplace(ctx_->scheduler, [this] { OnDrainTimeout(); });
  settle_timer_.emplace(ctx_->scheduler, [this] {
    if (!ctx_->stopped) ReleaseHeld();
  });
}

Session::~Session() {
  Close("session destroyed");
}

void Session::Start() {
  spdlog::info("{}: connected", name_);
  Reply("< hi >", false);
  Read();
}

void Session::Close(std::string_view reason) {
  if (closed_) return;
  closed_ = true;
  if (!ctx_->stopped) spdlog::info("{}: closed: {}", name_, reason);
  if (port_ != 0) {
    ctx_->broker.Detach(port_);
    port_ = 0;
  }
  settle_timer_.reset();
  drain_timer_.reset();
  asio::error_code ec;
  socket_.shutdown(asio::socket_base::shutdown_both, ec);
  socket_.close(ec);
  // What was queued for the client goes now, not when the server next prunes its closed sessions
  // (a client that never read may have left max_output_bytes here). writing_ stays: a write in
  // flight may still refer to it until its handler runs.
  std::string().swap(pending_);
  std::string().swap(held_);
  if (ctx_->stats.sessions_open > 0) --ctx_->stats.sessions_open;
}

// ---- reading and commands

void Session::Read() {
  if (reading_ || closing_ || closed_ || draining_) return;
  if (paused_ && reader_.Buffered() >= kPausedReadAhead) return;  // TCP backpressure
  reading_ = true;
  socket_.async_read_some(
      asio::buffer(read_buffer_),
      [self = shared_from_this()](const asio::error_code& ec, std::size_t n) { self->OnRead(ec, n); });
}

void Session::OnRead(const asio::error_code& ec, std::size_t n) {
  reading_ = false;
  if (closed_ || ctx_->stopped) return;
  if (ec == asio::error::eof) {
    StartDrain();
    return;
  }
  if (ec) {
    Close("read failed: " + ec.message());
    return;
  }
  reader_.Feed(std::string_view(read_buffer_.data(), n));
  Process();
}

void Session::Process() {
  while (!closed_ && !closing_) {
    if (port_ != 0 && BacklogFull()) {
      paused_ = true;  // TxConfirmed / ControllerChanged resume
      break;
    }
    const ElementReader::Result r = reader_.Next();
    if (r.status == ElementReader::Status::kNeedMore) break;
    if (r.status == ElementReader::Status::kTooLong) {
      ++ctx_->stats.protocol_errors;
      Close("command longer than " + std::to_string(kMaxElementLength) + " bytes");
      return;
    }
    Handle(r.element);
  }
  if (closed_) return;
  if (draining_) {
    CheckDrained();
  } else {
    Read();
  }
}

void Session::StartDrain() {
  draining_ = true;
  pending_.clear();  // nobody reads any more
  held_.clear();
  holding_ = false;
  Process();
}

void Session::CheckDrained() {
  if (closed_ || !draining_ || paused_) return;  // paused: Process runs again when the bus moves
  const std::size_t queued = port_ == 0 ? 0 : ctx_->broker.Port(port_).queued;
  if (queued == 0) {
    Close("client closed the connection");
    return;
  }
  if (!drain_timer_->Armed()) drain_timer_->StartAfter(ctx_->options.drain_timeout);
}

void Session::OnDrainTimeout() {
  if (closed_ || ctx_->stopped) return;
  const std::size_t left = port_ == 0 ? 0 : ctx_->broker.Port(port_).queued;
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(ctx_->options.drain_timeout).count();
  Close("client closed the connection; " + std::to_string(left) + " of its frames were still queued after " +
        std::to_string(ms) + " ms and are dropped");
}

void Session::Handle(std::string_view element) {
  const Command cmd = ParseCommand(element);
  const bool raw = mode_ == Mode::kRaw;
  if (mode_ == Mode::kNoBus) {
    // socketcand's NO_BUS state knows "open" only (and bus configuration, not served here).
    switch (cmd.kind) {
      case CommandKind::kOpen:
        Open(cmd.argument);
        return;
      case CommandKind::kEcho:
        Reply("< echo >", false);
        return;
      case CommandKind::kMalformed:
        if (cmd.argument == "open") {
          ++ctx_->stats.protocol_errors;
          Fail("< error could not open bus >", std::string("bad open command: ") + cmd.error);
          return;
        }
        break;
      case CommandKind::kBusConfig:
        ProtocolError(element, "bus configuration is not served");
        Reply("< error bus configuration not supported >", false);
        return;
      default:
        break;
    }
    ProtocolError(element, "unknown command before open");
    Reply("< error unknown command >", false);
    return;
  }

  switch (cmd.kind) {
    case CommandKind::kRawMode:
      if (!raw) EnterRaw();
      Reply("< ok >", false);  // a handshake reply: never padded
      if (!raw && holding_) settle_after_ = queued_bytes_;
      return;
    case CommandKind::kBcmMode:
      mode_ = Mode::kBcm;
      holding_ = false;
      settle_after_.reset();
      held_.clear();
      settle_timer_->Cancel();
      Reply("< ok >", false);
      return;
    case CommandKind::kEcho:
      Reply("< echo >", raw);
      return;
    case CommandKind::kSend:
    case CommandKind::kSendRtr:
      SubmitFrame(cmd.frame);
      return;
    case CommandKind::kMalformed:
      if (cmd.argument == "send" || cmd.argument == "sendrtr") {
        ProtocolError(element, cmd.error);  // socketcand: "Syntax error in send command", no reply
        return;
      }
      break;
    case CommandKind::kIsotpMode:
    case CommandKind::kControlMode:
      ProtocolError(element, "mode not served");
      Reply("< error mode not supported >", raw);
      return;
    case CommandKind::kBcmCommand:
      if (!raw) {
        ProtocolError(element, "broadcast-manager jobs are not served");
        Reply("< error command not supported >", false);
        return;
      }
      break;
    default:
      break;
  }
  ProtocolError(element, "unknown command");
  Reply("< error unknown command >", raw);
}

void Session::Open(std::string_view bus) {
  if (!ctx_->Serves(bus)) {
    ++ctx_->stats.protocol_errors;
    Fail("< error could not open bus >",
         "client asked for bus '" + Printable(bus) + "', which is not served");
    return;
  }
  try {
    port_ = ctx_->broker.Attach(bus, "socketcand " + peer_, *this);
  } catch (const std::invalid_argument& e) {
    Fail("< error could not open bus >", std::string("attach failed: ") + e.what());
    return;
  }
  spdlog::info("{}: opened {}", name_, bus);
  mode_ = Mode::kBcm;
  Reply("< ok >", false);
}

void Session::SubmitFrame(const CanFrame& frame) {
  if (ctx_->broker.Submit(port_, frame) == 1) {
    ++tx_backlog_;
    ++ctx_->stats.frames_from_clients;
  } else {
    ++ctx_->stats.submit_drops;  // bus-off or queue full: dropped, as a CAN driver would
  }
}

bool Session::BacklogFull() {
  if (tx_backlog_ < ctx_->options.max_tx_backlog) return false;
  tx_backlog_ = ctx_->broker.Port(port_).queued;  // our count misses frames flushed at bus-off
  return tx_backlog_ >= ctx_->options.max_tx_backlog;
}

void Session::ScheduleResume() {
  if (!paused_ && !draining_) return;
  // Not from inside the broker's callback: Process() submits, and Submit is best called from a
  // clean stack.
  asio::post(socket_.get_executor(), [self = shared_from_this()] {
    if (self->closed_ || self->ctx_->stopped) return;
    if (self->paused_) {
      self->paused_ = false;
      self->Process();
    } else {
      self->CheckDrained();
    }
  });
}

void Session::ProtocolError(std::string_view element, std::string_view why) {
  ++ctx_->stats.protocol_errors;
  ++protocol_errors_;
  if (protocol_errors_ <= kLoggedProtocolErrors) {
    spdlog::warn(
        "{}: ignored '{}': {}{}", name_, Printable(element), why,
        protocol_errors_ == kLoggedProtocolErrors ? " (further errors of this client are not logged)" : "");
  }
}

// ---- broker side

void Session::Deliver(std::span<const broker::TimedFrame> frames) {
  if (closed_ || closing_ || draining_ || mode_ != Mode::kRaw) return;
  std::string& out = holding_ ? held_ : pending_;
  const bool aligned = ctx_->options.align_frames;
  for (const auto& f : frames) {
    if (out.size() >= ctx_->options.max_output_bytes) {
      ++ctx_->stats.output_drops;
      if (!slow_.Dropping())
        spdlog::warn("{}: client does not keep up; dropping frames ({} bytes waiting)", name_, out.size());
      if (slow_.Dropped(1, transport::SlowReader::Clock::now()) && !slow_close_posted_) {
        // Not now: this runs inside the broker's delivery, which must not see its port go.
        slow_close_posted_ = true;
        asio::post(socket_.get_executor(), [self = shared_from_this()] {
          ++self->ctx_->stats.slow_clients;
          spdlog::warn("{}: {}; disconnected", self->name_, self->slow_.Reason("frames"));
          self->Close(self->slow_.Reason("frames"));
        });
      }
      continue;
    }
    const std::size_t before = out.size();
    if (!AppendFrame(out, f.frame, ctx_->origin + f.time, aligned)) continue;
    ++ctx_->stats.frames_to_clients;
    if (!holding_) queued_bytes_ += out.size() - before;
  }
  Write();
}

void Session::ControllerChanged(const ControllerEvent& event) {
  spdlog::info("{}: controller {} (TEC {}, REC {})", name_, ToString(event.state), event.tec, event.rec);
  if (event.state == ControllerState::kBusOff) tx_backlog_ = 0;  // the queue is flushed at bus-off
  ScheduleResume();
}

void Session::TxConfirmed(std::span<const broker::TimedFrame> frames) {
  tx_backlog_ -= std::min(tx_backlog_, frames.size());
  // Resume at half the limit, not at every confirmation: fewer wake-ups on a busy bus.
  if (!paused_ || tx_backlog_ <= ctx_->options.max_tx_backlog / 2) ScheduleResume();
}

// ---- writing

void Session::Reply(std::string_view message, bool pad) {
  if (draining_) return;  // the client is gone
  const std::size_t before = pending_.size();
  AppendMessage(pending_, message, pad && ctx_->options.align_frames);
  queued_bytes_ += pending_.size() - before;
  Write();
}

void Session::Fail(std::string_view message, std::string reason) {
  Reply(message, false);
  closing_ = true;
  closing_reason_ = std::move(reason);
  Write();
}

void Session::EnterRaw() {
  mode_ = Mode::kRaw;
  if (ctx_->options.raw_settle <= Duration::zero()) return;
  holding_ = true;
}

void Session::ReleaseHeld() {
  if (closed_ || !holding_) return;
  holding_ = false;
  queued_bytes_ += held_.size();
  pending_ += held_;
  held_.clear();
  Write();
}

void Session::Write() {
  if (write_active_ || closed_ || draining_) return;
  if (written_ == writing_.size()) {
    writing_.clear();
    written_ = 0;
    if (pending_.empty()) {
      slow_.CaughtUp();
      if (closing_) Close(closing_reason_);
      return;
    }
    std::swap(pending_, writing_);  // pending_ keeps writing_'s old capacity: no allocation
  }
  const std::size_t chunk = std::min(writing_.size() - written_, kWriteChunk);
  write_active_ = true;
  asio::async_write(
      socket_, asio::buffer(writing_.data() + written_, chunk),
      [self = shared_from_this()](const asio::error_code& ec, std::size_t n) { self->OnWrite(ec, n); });
}

void Session::OnWrite(const asio::error_code& ec, std::size_t n) {
  write_active_ = false;
  if (closed_ || ctx_->stopped || draining_) return;  // draining: the client is gone, errors expected
  if (ec) {
    Close("write failed: " + ec.message());
    return;
  }
  written_ += n;
  written_bytes_ += n;
  if (settle_after_ && written_bytes_ >= *settle_after_) {
    settle_after_.reset();
    if (holding_) settle_timer_->StartAfter(ctx_->options.raw_settle);
  }
  Write();
}

}  // namespace canfleet::socketcand::detail
