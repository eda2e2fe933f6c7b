#include "orchestrator/transport/broker_server.hpp"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <asio/generic/stream_protocol.hpp>
#include <asio/ip/address.hpp>
#include <asio/post.hpp>
#include <asio/steady_timer.hpp>
#include <stdexcept>

#include "bus/wire/message_writer.hpp"
#include "bus/wire/tcp_endpoint_text.hpp"
#include "orchestrator/transport/node_session.hpp"
#include "orchestrator/transport/unix_socket_path.hpp"

namespace canfleet::transport {

namespace {

/// After a failed accept (e.g. out of file descriptors), wait this long before the next one
/// instead of spinning.
constexpr std::chrono::milliseconds kAcceptRetry{100};

/// What a refused client reads: the HelloReply it waits for, refused with the reason.
std::string RefusalBytes(const std::string& reason) {
  wire::HelloReply reply;
  reply.set_accepted(false);
  reply.set_reason(reason);
  reply.set_protocol_version(wire::kProtocolVersion);
  wire::MessageWriter writer;
  writer.AddHelloReply(reply);
  const auto bytes = writer.Bytes();
  return std::string(reinterpret_cast<const char*>(bytes.data()), bytes.size());
}

}  // namespace

BrokerServer::BrokerServer(asio::io_context& io, broker::Broker& broker, BrokerServerOptions options)
    : io_(io), broker_(broker), options_(options) {}

BrokerServer::~BrokerServer() {
  Close();
}

wire::Endpoint BrokerServer::Listen(const wire::Endpoint& endpoint) {
  if (closed_) throw std::logic_error("BrokerServer::Listen after Close");
  wire::Endpoint bound = endpoint;
  if (endpoint.kind == wire::Endpoint::Kind::kTcp) {
    asio::ip::tcp::resolver resolver(io_);
    // Startup only: a blocking resolve of the listen address is fine here.
    const auto results =
        resolver.resolve(endpoint.host, std::to_string(endpoint.port), asio::ip::tcp::resolver::passive);
    const asio::ip::tcp::endpoint ep = results.begin()->endpoint();
    auto acceptor = std::make_unique<asio::ip::tcp::acceptor>(io_, ep, /*reuse_address=*/true);
    bound.port = acceptor->local_endpoint().port();
    auto policy = wire::PolicyFor(ep.address(), options_.token, "the broker");
    policy.handshake_timeout = options_.hello_timeout;
    if (policy.required)
      spdlog::info("listening on {}, which other hosts can reach: nodes and tools must send the token",
                   bound.ToString());
    tcp_policies_.push_back(std::move(policy));
    tcp_.push_back(std::move(acceptor));
    AcceptTcp(tcp_.size() - 1);
  } else {
    ClaimUnixSocketPath(endpoint.path);
    auto acceptor = std::make_unique<asio::local::stream_protocol::acceptor>(
        io_, asio::local::stream_protocol::endpoint(endpoint.path));
    unix_paths_.push_back(endpoint.path);
    unix_.push_back(std::move(acceptor));
    AcceptUnix(unix_.size() - 1);
  }
  endpoints_.push_back(bound);
  spdlog::info("listening on {}", bound.ToString());
  return bound;
}

void BrokerServer::AcceptTcp(std::size_t index) {
  tcp_[index]->async_accept([this, index, alive = std::weak_ptr<int>(alive_)](const asio::error_code& ec,
                                                                              asio::ip::tcp::socket socket) {
    if (alive.expired() || closed_) return;
    if (ec) {
      OnAccept(ec, "tcp", asio::generic::stream_protocol::socket(io_));
      auto timer = std::make_shared<asio::steady_timer>(io_, kAcceptRetry);
      timer->async_wait([this, index, timer, alive](const asio::error_code& wait_ec) {
        if (!wait_ec && !alive.expired() && !closed_) AcceptTcp(index);
      });
      return;
    }
    asio::error_code ignored;
    socket.set_option(asio::ip::tcp::no_delay(true), ignored);  // batches are whole when written
    std::string peer = "tcp";
    const auto remote = socket.remote_endpoint(ignored);
    if (!ignored) peer = "tcp " + wire::TcpEndpointText(remote);
    Gate(index, std::move(peer), std::move(socket));
    AcceptTcp(index);
  });
}

void BrokerServer::Gate(std::size_t index, std::string peer, asio::ip::tcp::socket socket) {
  if (gate_stats_->pending >= options_.max_pending) {
    // Checked before anything is allocated for the client (see ControlServer::Accept).
    if (!gate_full_logged_)
      spdlog::warn("{} connections are waiting to say who they are; closing new ones ({})",
                   options_.max_pending, peer);
    gate_full_logged_ = true;
    stats_->refused_connections++;
    asio::error_code ignored;
    socket.close(ignored);
    return;
  }
  gate_full_logged_ = false;
  wire::AuthGateHandlers<asio::ip::tcp::socket> handlers;
  handlers.admit = [this, peer, alive = std::weak_ptr<int>(alive_)](asio::ip::tcp::socket admitted) {
    if (alive.expired() || closed_) return;
    asio::error_code ignored;
    const auto protocol = admitted.local_endpoint(ignored).protocol();
    OnAccept(
        {}, peer,
        asio::generic::stream_protocol::socket(
            io_, asio::generic::stream_protocol(protocol.family(), protocol.protocol()), admitted.release()));
  };
  handlers.refusal = [](const std::string& reason) { return RefusalBytes(reason); };
  handlers.log_refusal = [stats = stats_, peer](const std::string& reason) {
    stats->refused_connections++;
    spdlog::warn("refused {}: {}", peer, reason);
  };
  wire::AuthGate<asio::ip::tcp::socket>::Run(std::move(socket), tcp_policies_[index], std::move(handlers),
                                             gate_stats_);
}

void BrokerServer::AcceptUnix(std::size_t index) {
  unix_[index]->async_accept([this, index, alive = std::weak_ptr<int>(alive_)](
                                 const asio::error_code& ec, asio::local::stream_protocol::socket socket) {
    if (alive.expired() || closed_) return;
    asio::generic::stream_protocol::socket generic(io_);
    if (!ec)
      generic = asio::generic::stream_protocol::socket(io_, asio::generic::stream_protocol(AF_UNIX, 0),
                                                       socket.release());
    OnAccept(ec, "unix " + unix_paths_[index], std::move(generic));
    if (ec) {
      auto timer = std::make_shared<asio::steady_timer>(io_, kAcceptRetry);
      timer->async_wait([this, index, timer, alive](const asio::error_code& wait_ec) {
        if (!wait_ec && !alive.expired() && !closed_) AcceptUnix(index);
      });
      return;
    }
    AcceptUnix(index);
  });
}

void BrokerServer::OnAccept(const asio::error_code& ec, std::string peer,
                            asio::generic::stream_protocol::socket socket) {
  if (ec) {
    spdlog::error("accepting a connection failed: {}; retrying in {} ms", ec.message(), kAcceptRetry.count());
    return;
  }
  stats_->accepted++;
  if (sessions_.size() >= options_.max_sessions) {
    const std::string reason =
        "too many connections to this broker (limit " + std::to_string(options_.max_sessions) + ")";
    stats_->refused_connections++;
    spdlog::warn("refused {}: {}", peer, reason);
    const std::string bytes = RefusalBytes(reason);
    asio::error_code ignored;
    socket.send(asio::buffer(bytes), asio::socket_base::message_flags(MSG_DONTWAIT | MSG_NOSIGNAL), ignored);
    socket.close(ignored);
    return;
  }
  const std::string label = "session " + std::to_string(next_session_++) + " (" + peer + ")";
  auto session = std::make_shared<detail::NodeSession>(
      broker_, options_, stats_, std::move(socket), label, [this](detail::NodeSession* s) { Remove(s); },
      &next_attach_);
  sessions_.emplace(session.get(), session);
  session->Start();
}

void BrokerServer::RequestNode(std::string_view bus, std::string_view node_name, wire::NodeRequest request,
                               NodeReplyHandler done) {
  stats_->node_requests++;
  detail::NodeSession* target = nullptr;
  for (const auto& [ptr, session] : sessions_) {
    if (!session->Attached() || session->Bus() != bus || session->NodeName() != node_name) continue;
    if (target == nullptr || session->AttachOrder() > target->AttachOrder()) target = ptr;
  }
  if (target == nullptr) {
    spdlog::debug("node request: no node {} on bus {}", node_name, bus);
    asio::post(io_, [done = std::move(done)] { done(std::nullopt); });
    return;
  }
  target->Request(std::move(request), std::move(done));
}

void BrokerServer::Remove(detail::NodeSession* session) {
  sessions_.erase(session);
}

void BrokerServer::Close() {
  if (closed_) return;
  closed_ = true;
  asio::error_code ignored;
  for (auto& a : tcp_)
    a->close(ignored);
  for (auto& a : unix_)
    a->close(ignored);
  for (const auto& path : unix_paths_)
    ::unlink(path.c_str());
  // Sessions remove themselves from the map while closing: close a copy.
  auto sessions = std::move(sessions_);
  sessions_.clear();
  for (auto& [ptr, session] : sessions)
    session->Close("broker shutting down", detail::NodeSession::Farewell::kError, spdlog::level::debug);
}

}  // namespace canfleet::transport
