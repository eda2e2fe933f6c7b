#include "orchestrator/control/control_session.hpp"

#include <asio/post.hpp>
#include <asio/write.hpp>
#include <exception>

namespace canfleet::control::detail {

namespace {

/// The Responder handed to the handler: forwards to its session while the session exists.
class SessionResponder final : public Responder {
 public:
  explicit SessionResponder(std::weak_ptr<ControlSession> session) : session_(std::move(session)) {}

  void Send(const Response& response) override {
    const auto s = session_.lock();
    if (!s) return;
    s->Send(response);
    ++sent_;
    if (on_sent_) on_sent_();
  }
  std::uint64_t Sent() const override { return sent_; }
  void OnSent(std::function<void()> hook) override { on_sent_ = std::move(hook); }
  bool Closed() const override {
    const auto s = session_.lock();
    return !s || s->Closed();
  }
  void OnClose(std::function<void()> handler) override {
    if (const auto s = session_.lock()) {
      s->OnClose(std::move(handler));
      return;
    }
    if (handler) handler();
  }

 private:
  std::weak_ptr<ControlSession> session_;
  std::uint64_t sent_ = 0;
  std::function<void()> on_sent_;
};

Response ErrorResponse(std::uint64_t id, std::string error) {
  Response r;
  r.set_id(id);
  r.set_error(std::move(error));
  return r;
}

}  // namespace

ControlSession::ControlSession(asio::ip::tcp::socket socket, ControlHandler& handler,
                               const ControlServerOptions& options, std::shared_ptr<ControlServerStats> stats,
                               std::string label, ClosedHandler on_closed)
    : socket_(std::move(socket)),
      handler_(handler),
      options_(options),
      stats_(std::move(stats)),
      linger_(socket_.get_executor()),
      incomplete_(socket_.get_executor()),
      label_(std::move(label)),
      on_closed_(std::move(on_closed)),
      reader_(options.max_message),
      slow_(options.slow_reader_limit) {}

void ControlSession::Start() {
  responder_ = std::make_shared<SessionResponder>(weak_from_this());
  spdlog::debug("{}: connected", label_);
  Read();
}

void ControlSession::Read() {
  socket_.async_read_some(asio::buffer(read_buffer_), [this, self = shared_from_this()](
                                                          const asio::error_code& ec, std::size_t n) {
    if (closed_) return;
    if (ec) {
      Close(ec == asio::error::eof ? "client disconnected" : ec.message(), false, spdlog::level::debug);
      return;
    }
    reader_.Append(read_buffer_.data(), n);
    for (;;) {
      const auto result = reader_.Next(request_);
      if (result == DelimitedReader::Result::kNeedMore) break;
      if (result == DelimitedReader::Result::kError) {
        ProtocolError(reader_.Error());
        return;
      }
      Dispatch(request_);
      if (closed_) return;  // the handler closed the server (a Shutdown)
    }
    WatchIncomplete();
    Read();
  });
}

void ControlSession::WatchIncomplete() {
  // A message begun must be finished within message_timeout: a client that sends part of one (a
  // length prefix of 1 MiB, then nothing) would otherwise hold that memory for as long as it likes.
  if (reader_.Buffered() == 0) {
    incomplete_since_armed_ = false;
    incomplete_.cancel();
    return;
  }
  if (incomplete_since_armed_) return;
  incomplete_since_armed_ = true;
  incomplete_.expires_after(options_.message_timeout);
  incomplete_.async_wait([this, self = shared_from_this()](const asio::error_code& ec) {
    if (ec || closed_ || !incomplete_since_armed_) return;
    ProtocolError("a message begun " + std::to_string(options_.message_timeout.count()) +
                  " ms ago is still incomplete (" + std::to_string(reader_.Buffered()) + " bytes)");
  });
}

void ControlSession::Dispatch(const Request& request) {
  if (request.body_case() == Request::BODY_NOT_SET) {
    // Unknown fields parse fine: this is most likely a newer client's request type.
    Send(ErrorResponse(request.id(), "request " + std::to_string(request.id()) +
                                         " has no body this orchestrator knows (a newer client?)"));
    return;
  }
  stats_->requests++;
  try {
    handler_.Handle(request, responder_);
  } catch (const std::exception& e) {
    spdlog::error("{}: request {} failed: {}", label_, request.id(), e.what());
    Send(ErrorResponse(request.id(), std::string("internal error: ") + e.what()));
  }
}

void ControlSession::ProtocolError(const std::string& reason) {
  stats_->protocol_errors++;
  Send(ErrorResponse(0, "protocol error: " + reason));
  Close("protocol error: " + reason, true, spdlog::level::warn);
}

void ControlSession::Send(const Response& response) {
  if (closed_) return;
  if (response.has_frames() && filling_.size() >= options_.max_backlog_bytes) {
    if (!slow_.Dropping()) spdlog::warn("{}: client not reading; dropping frame batches", label_);
    stats_->dropped_batches++;
    if (slow_.Dropped(1, transport::SlowReader::Clock::now()) && !slow_close_posted_) {
      // Not now: a dump's batches are sent from inside the broker's delivery.
      slow_close_posted_ = true;
      asio::post(socket_.get_executor(), [this, self = shared_from_this()] {
        stats_->slow_readers++;
        Close(slow_.Reason("frame batches"), false, spdlog::level::warn);
      });
    }
    return;
  }
  if (!AppendDelimited(response, filling_, options_.max_message)) {
    spdlog::error("{}: response {} of {} bytes exceeds the limit of {}", label_, response.id(),
                  response.ByteSizeLong(), options_.max_message);
    AppendDelimited(
        ErrorResponse(response.id(), "response too large (" + std::to_string(response.ByteSizeLong()) +
                                         " bytes, limit " + std::to_string(options_.max_message) + ")"),
        filling_, options_.max_message);
  }
  Flush();
}

void ControlSession::OnClose(std::function<void()> handler) {
  if (!handler) return;
  if (closed_) {
    handler();
    return;
  }
  close_handlers_.push_back(std::move(handler));
}

void ControlSession::Close(const std::string& reason, bool drain, spdlog::level::level_enum level) {
  if (closed_) return;
  const auto self = shared_from_this();  // on_closed_ drops the server's reference
  closed_ = true;
  spdlog::log(level, "{}: closed: {}", label_, reason);
  if (on_closed_) {
    on_closed_(this);
    on_closed_ = nullptr;
  }
  // Handlers may capture the Responder; running and dropping them breaks any cycle through it.
  auto handlers = std::move(close_handlers_);
  close_handlers_.clear();
  for (auto& h : handlers)
    h();
  if (!drain || !socket_.is_open() || (!write_in_flight_ && filling_.empty())) {
    CloseSocket();
    return;
  }
  Flush();
  linger_.expires_after(options_.close_linger);
  linger_.async_wait([this, self](const asio::error_code& ec) {
    if (!ec) CloseSocket();
  });
}

void ControlSession::Flush() {
  if (write_in_flight_ || filling_.empty() || !socket_.is_open()) return;
  writing_.swap(filling_);
  filling_.clear();
  write_in_flight_ = true;
  asio::async_write(socket_, asio::buffer(writing_),
                    [this, self = shared_from_this()](const asio::error_code& ec, std::size_t) {
                      write_in_flight_ = false;
                      writing_.clear();
                      if (ec) {
                        if (closed_)
                          CloseSocket();
                        else
                          Close(ec.message(), false, spdlog::level::debug);
                        return;
                      }
                      if (!filling_.empty()) {
                        Flush();
                        return;
                      }
                      if (closed_) {
                        CloseSocket();
                        return;
                      }
                      if (const auto lost = slow_.CaughtUp(); lost != 0)
                        spdlog::warn("{}: reading again; {} frame batches were dropped", label_, lost);
                    });
}

void ControlSession::CloseSocket() {
  asio::error_code ignored;
  linger_.cancel();
  incomplete_.cancel();
  socket_.shutdown(asio::socket_base::shutdown_both, ignored);
  socket_.close(ignored);
}

}  // namespace canfleet::control::detail
