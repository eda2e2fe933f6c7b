#include "orchestrator/socketcand/server.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <asio/error.hpp>
#include <asio/ip/address.hpp>
#include <asio/ip/tcp.hpp>
#include <stdexcept>

#include "orchestrator/socketcand/session.hpp"

namespace canfleet::socketcand {
namespace detail {

/// Creates, registers and starts the session of a connected client.
void StartSession(const std::shared_ptr<Context>& ctx, asio::generic::stream_protocol::socket socket,
                  std::string_view bus, std::string peer);

struct Listener : std::enable_shared_from_this<Listener> {
  Listener(std::shared_ptr<Context> c, std::string b)
      : ctx(std::move(c)), bus(std::move(b)), acceptor(ctx->io) {
    retry.emplace(ctx->scheduler, [this] {
      if (!ctx->stopped) Accept();
    });
  }

  void Accept();
  void OnAccept(const asio::error_code& ec, asio::ip::tcp::socket socket);
  /// Also destroys the retry timer: a pending accept may keep the listener beyond the scheduler.
  void Close() {
    retry.reset();
    asio::error_code ec;
    acceptor.close(ec);
  }

  std::shared_ptr<Context> ctx;
  std::string bus;
  asio::ip::tcp::acceptor acceptor;
  std::optional<Timer> retry;  ///< after a failed accept (out of file descriptors...)
};

void Listener::Accept() {
  acceptor.async_accept(
      [self = shared_from_this()](const asio::error_code& ec, asio::ip::tcp::socket socket) {
        self->OnAccept(ec, std::move(socket));
      });
}

void Listener::OnAccept(const asio::error_code& ec, asio::ip::tcp::socket socket) {
  if (ctx->stopped || ec == asio::error::operation_aborted) return;
  if (ec) {
    // Typically EMFILE: retry later instead of spinning on a listener that keeps failing.
    spdlog::warn("socketcand {}: accept failed: {}; retrying in 100 ms", bus, ec.message());
    if (retry) retry->StartAfter(std::chrono::milliseconds(100));
    return;
  }
  asio::error_code peer_ec;
  const auto peer = socket.remote_endpoint(peer_ec);
  if (ctx->stats.sessions_open >= ctx->options.max_sessions) {
    // Each session may queue max_output_bytes for its client: the number of them bounds the memory.
    ++ctx->stats.sessions_refused;
    spdlog::warn("socketcand {}: refused {}: {} sessions open (the limit)", bus,
                 peer_ec ? std::string("unknown peer") : peer.address().to_string(),
                 ctx->options.max_sessions);
    static constexpr char kRefusal[] = "< error too many connections >";
    asio::error_code ignored;
    socket.send(asio::buffer(kRefusal, sizeof kRefusal - 1), asio::socket_base::message_flags(MSG_DONTWAIT),
                ignored);
    socket.close(ignored);
    Accept();
    return;
  }
  socket.set_option(asio::ip::tcp::no_delay(true), peer_ec);  // as socketcand: one frame, one segment
  StartSession(
      ctx, asio::generic::stream_protocol::socket(std::move(socket)), bus,
      peer_ec ? std::string("unknown peer") : peer.address().to_string() + ":" + std::to_string(peer.port()));
  Accept();
}

void StartSession(const std::shared_ptr<Context>& ctx, asio::generic::stream_protocol::socket socket,
                  std::string_view bus, std::string peer) {
  auto& sessions = ctx->sessions;
  sessions.erase(std::remove_if(sessions.begin(), sessions.end(), [](const auto& s) { return s->closed(); }),
                 sessions.end());
  auto session = std::make_shared<Session>(ctx, std::move(socket), bus, std::move(peer));
  sessions.push_back(session);
  ++ctx->stats.sessions_accepted;
  ++ctx->stats.sessions_open;
  session->Start();
}

}  // namespace detail

Server::Server(asio::io_context& io, broker::Broker& broker, Scheduler& scheduler, ServerOptions options)
    : context_(std::make_shared<detail::Context>(io, broker, scheduler, std::move(options))) {
  // The process's one wall-clock origin when given (host::BrokerHost gives it), else read now.
  context_->origin = context_->options.wall_origin.value_or(WallClockOrigin(scheduler));
}

Server::~Server() {
  Stop();
}

std::uint16_t Server::Serve(std::string_view bus, std::optional<std::uint16_t> port) {
  CheckServable(bus);
  const std::uint16_t wanted = port.value_or(static_cast<std::uint16_t>(kDefaultPort + listeners_.size()));

  auto listener = std::make_shared<detail::Listener>(context_, std::string(bus));
  const asio::ip::tcp::endpoint endpoint(asio::ip::make_address(context_->options.bind_address), wanted);
  listener->acceptor.open(endpoint.protocol());
  listener->acceptor.set_option(asio::ip::tcp::acceptor::reuse_address(true));
  listener->acceptor.bind(endpoint);
  listener->acceptor.listen();
  const std::uint16_t bound = listener->acceptor.local_endpoint().port();

  context_->stopped = false;
  context_->buses.emplace_back(bus);
  listeners_.push_back(listener);
  listener->Accept();
  spdlog::info("socketcand: serving {} on {}:{}", bus, context_->options.bind_address, bound);
  if (!endpoint.address().is_loopback())
    // The socketcand protocol has no authentication: whoever reaches this port can read and write
    // the bus. Asked for explicitly (--socketcand-bind), so said plainly rather than refused.
    spdlog::warn(
        "socketcand: {} on {}:{} is reachable from other hosts and the socketcand protocol has no "
        "authentication: anyone who reaches it can send frames on {} (keep it on 127.0.0.1, or firewall it)",
        bus, context_->options.bind_address, bound, bus);
  return bound;
}

void Server::CheckServable(std::string_view bus) const {
  const auto buses = context_->broker.Buses();
  if (std::find(buses.begin(), buses.end(), bus) == buses.end())
    throw std::invalid_argument("socketcand: unknown bus " + std::string(bus));
  if (context_->Serves(bus))
    throw std::invalid_argument("socketcand: bus " + std::string(bus) + " is already served");
}

void Server::Offer(std::string_view bus) {
  CheckServable(bus);
  context_->stopped = false;
  context_->buses.emplace_back(bus);
}

void Server::Adopt(asio::generic::stream_protocol::socket socket, std::string_view bus, std::string peer) {
  if (!context_->Serves(bus))
    throw std::invalid_argument("socketcand: bus " + std::string(bus) + " is not served");
  detail::StartSession(context_, std::move(socket), bus, std::move(peer));
}

void Server::Stop() {
  if (context_->stopped) return;
  context_->stopped = true;
  for (auto& l : listeners_)
    l->Close();
  listeners_.clear();
  context_->buses.clear();
  auto sessions = std::move(context_->sessions);
  context_->sessions.clear();
  for (auto& s : sessions)
    s->Close("server stopped");
}

ServerStats Server::Stats() const {
  return context_->stats;
}

}  // namespace canfleet::socketcand
