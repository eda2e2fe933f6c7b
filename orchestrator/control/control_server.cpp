#include "orchestrator/control/control_server.hpp"

#include <spdlog/spdlog.h>

#include <asio/steady_timer.hpp>
#include <stdexcept>

#include "bus/wire/tcp_endpoint_text.hpp"
#include "orchestrator/control/control_session.hpp"

namespace canfleet::control {

namespace {

/// After a failed accept (e.g. out of file descriptors), wait this long before the next one
/// instead of spinning.
constexpr std::chrono::milliseconds kAcceptRetry{100};

/// What a refused client reads: an error Response with id 0, as for a protocol error.
std::string RefusalBytes(const std::string& reason, std::size_t max_message) {
  Response response;
  response.set_id(0);
  response.set_error("refused: " + reason);
  std::string bytes;
  AppendDelimited(response, bytes, max_message);
  return bytes;
}

}  // namespace

ControlServer::ControlServer(asio::io_context& io, ControlHandler& handler, ControlServerOptions options)
    : io_(io), handler_(handler), options_(options) {}

ControlServer::~ControlServer() {
  Close();
}

asio::ip::tcp::endpoint ControlServer::Listen(const std::string& endpoint) {
  if (closed_) throw std::logic_error("ControlServer::Listen after Close");
  const wire::Endpoint parsed = ParseControlEndpoint(endpoint);
  asio::ip::tcp::resolver resolver(io_);
  // Startup only: a blocking resolve of the listen address is fine here.
  const auto results =
      resolver.resolve(parsed.host, std::to_string(parsed.port), asio::ip::tcp::resolver::passive);
  const asio::ip::tcp::endpoint ep = results.begin()->endpoint();
  auto acceptor = std::make_unique<asio::ip::tcp::acceptor>(io_, ep, /*reuse_address=*/true);
  const asio::ip::tcp::endpoint bound = acceptor->local_endpoint();
  auto policy = wire::PolicyFor(ep.address(), options_.token, "the control API");
  policy.handshake_timeout = options_.handshake_timeout;
  if (policy.required)
    spdlog::info(
        "control API listening on tcp://{}, which other hosts can reach: clients must send the token",
        wire::TcpEndpointText(bound));
  else
    spdlog::debug("control API listening on tcp://{}", wire::TcpEndpointText(bound));
  policies_.push_back(std::move(policy));
  acceptors_.push_back(std::move(acceptor));
  endpoints_.push_back(bound);
  Accept(acceptors_.size() - 1);
  return bound;
}

void ControlServer::Accept(std::size_t index) {
  acceptors_[index]->async_accept([this, index, alive = std::weak_ptr<int>(alive_)](
                                      const asio::error_code& ec, asio::ip::tcp::socket socket) {
    if (alive.expired() || closed_) return;
    if (ec) {
      spdlog::error("control API: accepting a connection failed: {}; retrying in {} ms", ec.message(),
                    kAcceptRetry.count());
      auto timer = std::make_shared<asio::steady_timer>(io_, kAcceptRetry);
      timer->async_wait([this, index, timer, alive](const asio::error_code& wait_ec) {
        if (!wait_ec && !alive.expired() && !closed_) Accept(index);
      });
      return;
    }
    asio::error_code ignored;
    socket.set_option(asio::ip::tcp::no_delay(true), ignored);
    std::string peer = "tcp";
    const auto remote = socket.remote_endpoint(ignored);
    if (!ignored) peer = wire::TcpEndpointText(remote);
    stats_->accepted++;
    if (gate_stats_->pending >= options_.max_pending) {
      // Checked before anything is allocated for the client: a flood of silent connections
      // costs one descriptor each for at most the handshake timeout, and no more of them.
      if (!gate_full_logged_)
        spdlog::warn("control API: {} connections are waiting to say who they are; closing new ones ({})",
                     options_.max_pending, peer);
      gate_full_logged_ = true;
      stats_->refused++;
      socket.close(ignored);
    } else {
      gate_full_logged_ = false;
      wire::AuthGateHandlers<asio::ip::tcp::socket> handlers;
      handlers.admit = [this, peer, alive](asio::ip::tcp::socket admitted) {
        if (!alive.expired() && !closed_) Admit(std::move(admitted), peer);
      };
      handlers.refusal = [max = options_.max_message](const std::string& reason) {
        return RefusalBytes(reason, max);
      };
      handlers.log_refusal = [stats = stats_, peer](const std::string& reason) {
        stats->refused++;
        spdlog::warn("control API: refused {}: {}", peer, reason);
      };
      wire::AuthGate<asio::ip::tcp::socket>::Run(std::move(socket), policies_[index], std::move(handlers),
                                                 gate_stats_);
    }
    Accept(index);
  });
}

void ControlServer::Admit(asio::ip::tcp::socket socket, const std::string& peer) {
  if (sessions_.size() >= options_.max_sessions) {
    const std::string reason = "too many connections to this control API (limit " +
                               std::to_string(options_.max_sessions) + "); close one and try again";
    stats_->refused++;
    spdlog::warn("control API: refused {}: {}", peer, reason);
    const std::string bytes = RefusalBytes(reason, options_.max_message);
    asio::error_code ignored;
    socket.send(asio::buffer(bytes), asio::socket_base::message_flags(MSG_DONTWAIT | MSG_NOSIGNAL), ignored);
    socket.close(ignored);
    return;
  }
  const std::string label = "control session " + std::to_string(next_session_++) + " (" + peer + ")";
  auto session = std::make_shared<detail::ControlSession>(
      std::move(socket), handler_, options_, stats_, label, [this](detail::ControlSession* s) { Remove(s); });
  sessions_.emplace(session.get(), session);
  session->Start();
}

void ControlServer::Remove(detail::ControlSession* session) {
  sessions_.erase(session);
}

void ControlServer::Close() {
  if (closed_) return;
  closed_ = true;
  asio::error_code ignored;
  for (auto& a : acceptors_)
    a->close(ignored);
  // Sessions remove themselves from the map while closing: close a copy.
  std::vector<std::shared_ptr<detail::ControlSession>> sessions;
  sessions.reserve(sessions_.size());
  for (auto& [ptr, session] : sessions_)
    sessions.push_back(session);
  for (auto& s : sessions)
    s->Close("server closing", true, spdlog::level::debug);
  sessions_.clear();
}

}  // namespace canfleet::control
