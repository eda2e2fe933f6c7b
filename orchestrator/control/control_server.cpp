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
  if (!ep.address().is_loopback())
    spdlog::warn(
        "control API listening on tcp://{}, which other hosts can reach: anyone who can connect "
        "can drive the fleet",
        wire::TcpEndpointText(bound));
  else
    spdlog::debug("control API listening on tcp://{}", wire::TcpEndpointText(bound));
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
    const std::string label = "control session " + std::to_string(next_session_++) + " (" + peer + ")";
    auto session =
        std::make_shared<detail::ControlSession>(std::move(socket), handler_, options_, stats_, label,
                                                 [this](detail::ControlSession* s) { Remove(s); });
    sessions_.emplace(session.get(), session);
    session->Start();
    Accept(index);
  });
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
