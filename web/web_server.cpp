#include "web/web_server.hpp"

#include <google/protobuf/struct.pb.h>
#include <google/protobuf/util/json_util.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/asio/thread_pool.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <fstream>
#include <mutex>
#include <optional>
#include <random>
#include <regex>
#include <set>
#include <sstream>

#include "bus/wire/auth_token.hpp"
#include "tools/telemetry/event_format.hpp"
#include "web/action_forwarder.hpp"

namespace canfleet::web {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using Request = http::request<http::string_body>;
using Response = http::response<http::string_body>;

bool IsLoopback(const std::string& address) {
  boost::system::error_code ec;
  const auto a = net::ip::make_address(address, ec);
  return !ec && a.is_loopback();
}

namespace {

const char* ContentType(const std::string& name) {
  const auto dot = name.rfind('.');
  const std::string ext = dot == std::string::npos ? "" : name.substr(dot + 1);
  if (ext == "html") return "text/html; charset=utf-8";
  if (ext == "js") return "text/javascript; charset=utf-8";
  if (ext == "css") return "text/css; charset=utf-8";
  if (ext == "svg") return "image/svg+xml";
  if (ext == "png") return "image/png";
  return "application/octet-stream";
}

/// The control requests the page may send: the actions of the fault, I/O, NMT and SDO panels, and
/// the reads behind them.
bool AllowedAction(control::Request::BodyCase body) {
  switch (body) {
    case control::Request::kFaultInject:
    case control::Request::kFaultClear:
    case control::Request::kFaultList:
    case control::Request::kIoSet:
    case control::Request::kIoGet:
    case control::Request::kSdoRead:
    case control::Request::kSdoWrite:
    case control::Request::kNmt:
    case control::Request::kStatus:
      return true;
    default:
      return false;
  }
}

std::string ErrorJson(const std::string& message) {
  return "{\"ok\":false,\"error\":" + tools::JsonString(message) + "}";
}

}  // namespace

struct WebServer::Impl {
  Impl(WebState& s, WebServerOptions o) : state(s), options(std::move(o)) {}

  WebState& state;
  WebServerOptions options;
  net::io_context io{1};
  tcp::acceptor acceptor{io};
  net::thread_pool actions{1};
  std::atomic<std::size_t> live{0};
  mutable std::mutex stats_mutex;
  Stats stats;
  bool actions_enabled = false;
  bool token_required = false;

  void Count(std::uint64_t Stats::*field, std::uint64_t n = 1) {
    std::lock_guard lock(stats_mutex);
    stats.*field += n;
  }
  void Accept();
  Response Answer(const Request& req);
  std::string Info() const {
    return std::string("{\"actions\":") + (actions_enabled ? "true" : "false") +
           ",\"token_required\":" + (token_required ? "true" : "false") +
           ",\"read_only\":" + (options.read_only ? "true" : "false") +
           ",\"update_period_ms\":" + std::to_string(options.update_period.count()) + "}";
  }
};

namespace {

/// Counts itself among the live connections while it exists.
struct LiveCount {
  explicit LiveCount(std::atomic<std::size_t>& n) : live(n) { ++live; }
  ~LiveCount() { --live; }
  LiveCount(const LiveCount&) = delete;
  LiveCount& operator=(const LiveCount&) = delete;
  std::atomic<std::size_t>& live;
};

class WsSession : public std::enable_shared_from_this<WsSession> {
 public:
  WsSession(tcp::socket socket, WebServer::Impl& impl)
      : ws_(std::move(socket)), timer_(ws_.get_executor()), impl_(impl), count_(impl.live) {}

  void Start(Request req) {
    beast::get_lowest_layer(ws_).expires_never();
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.read_message_max(impl_.options.max_message_bytes);
    ws_.async_accept(req, [self = shared_from_this()](beast::error_code ec) {
      if (ec) return;
      self->Read();
      self->Tick();
    });
  }

 private:
  // The page sends what it plots ({"plot": ["io:can0:5/IN1.voltage_mV", ...]}); reading also notices
  // a close, and a message over the limit ends the session. Anything else is ignored.
  void Subscribe(const std::string& text) {
    google::protobuf::Struct message;
    if (!google::protobuf::util::JsonStringToMessage(text, &message).ok()) return;
    const auto it = message.fields().find("plot");
    if (it == message.fields().end() || !it->second.has_list_value()) return;
    std::set<std::string> plotted;
    for (const auto& v : it->second.list_value().values())
      if (v.has_string_value() && plotted.size() < 64) plotted.insert(v.string_value());
    for (const auto& name : plotted)
      if (!cursor_.plotted.contains(name)) cursor_.backfill.insert(name);
    cursor_.plotted = std::move(plotted);
  }
  void Read() {
    ws_.async_read(in_, [self = shared_from_this()](beast::error_code ec, std::size_t n) {
      if (ec) {
        self->closed_ = true;
        self->timer_.cancel();
        return;
      }
      self->Subscribe(beast::buffers_to_string(self->in_.data()));
      self->in_.consume(n);
      self->Read();
    });
  }
  void Tick() {
    if (closed_) return;
    // A client still reading the last update gets none meanwhile: the next one carries what is new.
    if (!writing_) {
      out_ = impl_.state.UpdateJson(cursor_, std::chrono::system_clock::now());
      writing_ = true;
      ws_.text(true);
      ws_.async_write(net::buffer(out_), [self = shared_from_this()](beast::error_code ec, std::size_t n) {
        self->writing_ = false;
        if (ec) {
          self->closed_ = true;
          self->timer_.cancel();
          return;
        }
        self->impl_.Count(&WebServer::Stats::ws_messages);
        self->impl_.Count(&WebServer::Stats::ws_bytes, n);
      });
    }
    timer_.expires_after(impl_.options.update_period);
    timer_.async_wait([self = shared_from_this()](beast::error_code ec) {
      if (!ec) self->Tick();
    });
  }

  websocket::stream<beast::tcp_stream> ws_;
  beast::flat_buffer in_;
  net::steady_timer timer_;
  WebServer::Impl& impl_;
  LiveCount count_;
  Cursor cursor_;
  std::string out_;
  bool writing_ = false;
  bool closed_ = false;
};

class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(tcp::socket socket, WebServer::Impl& impl)
      : stream_(std::move(socket)), impl_(impl), count_(std::make_unique<LiveCount>(impl.live)) {}

  void Start() { Read(); }

 private:
  void Read() {
    parser_.emplace();
    parser_->header_limit(8 * 1024);
    parser_->body_limit(impl_.options.max_body_bytes);
    stream_.expires_after(impl_.options.request_timeout);
    http::async_read(stream_, buffer_, *parser_,
                     [self = shared_from_this()](beast::error_code ec, std::size_t) { self->OnRead(ec); });
  }

  void OnRead(beast::error_code ec) {
    if (ec == http::error::end_of_stream || ec == beast::error::timeout || ec == net::error::eof ||
        ec == net::error::connection_reset || ec == net::error::operation_aborted) {
      Close();
      return;
    }
    if (ec) {  // not HTTP, or over a limit: say so once, then close
      impl_.Count(&WebServer::Stats::bad_requests);
      Response res{ec == http::error::body_limit || ec == http::error::header_limit
                       ? http::status::payload_too_large
                       : http::status::bad_request,
                   11};
      res.set(http::field::content_type, "application/json");
      res.body() = ErrorJson(ec.message());
      res.keep_alive(false);
      res.prepare_payload();
      Write(std::move(res));
      return;
    }
    impl_.Count(&WebServer::Stats::requests);
    Request req = parser_->release();
    if (websocket::is_upgrade(req)) {
      if (req.target() != "/ws") {
        Write(Plain(req, http::status::not_found, ErrorJson("no WebSocket at " + std::string(req.target()))));
        return;
      }
      count_.reset();  // the WebSocket session counts itself
      std::make_shared<WsSession>(stream_.release_socket(), impl_)->Start(std::move(req));
      return;
    }
    if (req.method() == http::verb::post && req.target() == "/api/action") {
      Action(std::move(req));
      return;
    }
    Write(impl_.Answer(req));
  }

  Response Plain(const Request& req, http::status status, std::string body) {
    Response res{status, req.version()};
    res.set(http::field::content_type, "application/json");
    res.keep_alive(req.keep_alive());
    res.body() = std::move(body);
    res.prepare_payload();
    return res;
  }

  void Action(Request req) {
    if (!impl_.actions_enabled) {
      Write(Plain(req, http::status::forbidden,
                  ErrorJson(impl_.options.control.empty() ? "read-only: this server has no control endpoint"
                                                          : "read-only: actions are off (--read-only)")));
      return;
    }
    const auto header = req[http::field::authorization];
    const std::string_view authorization(header.data(), header.size());
    constexpr std::string_view kBearer = "Bearer ";
    const bool token_ok = authorization.substr(0, kBearer.size()) == kBearer &&
                          wire::TokensEqual(impl_.options.token, authorization.substr(kBearer.size()));
    if (impl_.token_required && !token_ok) {
      spdlog::warn("canfleet web: refused an action from {}: {}", Peer(),
                   authorization.empty() ? "no token" : "wrong token");
      Write(Plain(
          req, http::status::forbidden,
          ErrorJson("actions need the token canfleet web printed at start (Authorization: Bearer ...)")));
      return;
    }
    control::Request request;
    const auto parsed = google::protobuf::util::JsonStringToMessage(req.body(), &request);
    if (!parsed.ok() || !AllowedAction(request.body_case())) {
      Write(Plain(req, http::status::bad_request,
                  ErrorJson(parsed.ok() ? "not an action the page may send"
                                        : "not a control Request in JSON: " + parsed.message().as_string())));
      return;
    }
    impl_.Count(&WebServer::Stats::actions);
    request.set_id(0);
    // On the worker: a control request may take seconds (an SDO transfer); the answer comes back here.
    net::post(impl_.actions, [self = shared_from_this(), request, req = std::move(req)]() mutable {
      const ForwardedAction forwarded = ForwardAction(self->impl_.options.control, request);
      const http::status status = forwarded.reached ? http::status::ok : http::status::bad_gateway;
      std::string body = forwarded.json;
      net::post(self->stream_.get_executor(),
                [self, req = std::move(req), status, body = std::move(body)]() mutable {
                  self->Write(self->Plain(req, status, std::move(body)));
                });
    });
  }

  void Write(Response res) {
    auto shared = std::make_shared<Response>(std::move(res));
    stream_.expires_after(impl_.options.request_timeout);
    http::async_write(stream_, *shared,
                      [self = shared_from_this(), shared](beast::error_code ec, std::size_t) {
                        if (ec || !shared->keep_alive()) {
                          self->Close();
                          return;
                        }
                        self->Read();
                      });
  }

  void Close() {
    beast::error_code ignored;
    stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
    stream_.close();
  }

  std::string Peer() {
    boost::system::error_code ec;
    const auto remote = stream_.socket().remote_endpoint(ec);
    return ec ? std::string("?") : remote.address().to_string() + ":" + std::to_string(remote.port());
  }

  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
  WebServer::Impl& impl_;
  std::unique_ptr<LiveCount> count_;
};

}  // namespace

Response WebServer::Impl::Answer(const Request& req) {
  Response res{http::status::ok, req.version()};
  res.keep_alive(req.keep_alive());
  res.set(http::field::cache_control, "no-store");
  const std::string target(req.target().substr(0, req.target().find('?')));
  if (req.method() != http::verb::get && req.method() != http::verb::head) {
    res.result(http::status::method_not_allowed);
    res.set(http::field::content_type, "application/json");
    res.body() = ErrorJson("GET, or POST /api/action");
  } else if (target == "/api/state") {
    Cursor fresh;
    res.set(http::field::content_type, "application/json");
    res.body() = state.UpdateJson(fresh, std::chrono::system_clock::now());
  } else if (target == "/api/node") {
    // ?key=BUS:ID, as the page's node view asks for it.
    std::string query(req.target().substr(std::min(req.target().size(), target.size() + 1)));
    if (const auto encoded = query.find("%3A"); encoded != std::string::npos) query.replace(encoded, 3, ":");
    const auto colon = query.rfind(':');
    int id = -1;
    if (query.starts_with("key=") && colon != std::string::npos) {
      try {
        id = std::stoi(query.substr(colon + 1));
      } catch (const std::exception&) {
      }
    }
    res.set(http::field::content_type, "application/json");
    if (id < 0 || id > 127) {
      res.result(http::status::bad_request);
      res.body() = ErrorJson("/api/node?key=BUS:NODE-ID");
    } else {
      res.body() = state.NodeJson(query.substr(4, colon - 4), static_cast<std::uint8_t>(id),
                                  std::chrono::system_clock::now());
    }
  } else if (target == "/api/info") {
    res.set(http::field::content_type, "application/json");
    res.body() = Info();
  } else {
    static const std::regex kAsset("/([a-z0-9_-]+\\.(html|js|css|svg|png))");
    std::smatch match;
    const std::string name = target == "/"                             ? "index.html"
                             : std::regex_match(target, match, kAsset) ? match[1].str()
                                                                       : std::string();
    std::ifstream file(options.static_dir / name, std::ios::binary);
    if (name.empty() || !file) {
      res.result(http::status::not_found);
      res.set(http::field::content_type, "application/json");
      res.body() = ErrorJson("not found: " + target);
    } else {
      std::ostringstream content;
      content << file.rdbuf();
      res.set(http::field::content_type, ContentType(name));
      res.body() = content.str();
    }
  }
  res.prepare_payload();
  return res;
}

void WebServer::Impl::Accept() {
  acceptor.async_accept(net::make_strand(io), [this](beast::error_code ec, tcp::socket socket) {
    if (ec == net::error::operation_aborted) return;
    if (!ec) {
      Count(&Stats::connections);
      if (live.load() >= options.max_connections) {
        // Over the limit: a short answer (it fits the socket's buffer: no wait) and close.
        Count(&Stats::refused);
        static const std::string kBusy =
            "HTTP/1.1 503 Service Unavailable\r\nContent-Length: 0\r\nConnection: close\r\n\r\n";
        socket.non_blocking(true, ec);
        socket.send(net::buffer(kBusy), 0, ec);
        socket.close(ec);
      } else {
        std::make_shared<HttpSession>(std::move(socket), *this)->Start();
      }
    }
    Accept();
  });
}

WebServer::WebServer(WebState& state, WebServerOptions options)
    : impl_(std::make_unique<Impl>(state, std::move(options))) {
  Impl& i = *impl_;
  boost::system::error_code ec;
  const auto address = net::ip::make_address(i.options.address, ec);
  if (ec) throw std::runtime_error("web: " + i.options.address + " is not an IP address");
  const tcp::endpoint endpoint(address, i.options.port);
  i.acceptor.open(endpoint.protocol(), ec);
  if (!ec) i.acceptor.set_option(net::socket_base::reuse_address(true), ec);
  if (!ec) i.acceptor.bind(endpoint, ec);
  if (!ec) i.acceptor.listen(net::socket_base::max_listen_connections, ec);
  if (ec)
    throw std::runtime_error("web: cannot listen on " + i.options.address + ":" +
                             std::to_string(i.options.port) + ": " + ec.message());
  i.actions_enabled = !i.options.read_only && !i.options.control.empty();
  i.token_required = i.actions_enabled && (!i.options.token.empty() || !IsLoopback(i.options.address));
  if (i.token_required && i.options.token.empty()) i.options.token = wire::GenerateToken();
  i.Accept();
}

WebServer::~WebServer() {
  Stop();
  impl_->actions.join();
}

std::uint16_t WebServer::Port() const {
  return impl_->acceptor.local_endpoint().port();
}

std::string WebServer::Url() const {
  const std::string host = impl_->options.address == "0.0.0.0" ? "127.0.0.1" : impl_->options.address;
  std::string url = "http://" + (host.find(':') != std::string::npos ? "[" + host + "]" : host) + ":" +
                    std::to_string(Port()) + "/";
  if (impl_->token_required) url += "#token=" + impl_->options.token;
  return url;
}

bool WebServer::ActionsEnabled() const {
  return impl_->actions_enabled;
}

const std::string& WebServer::Token() const {
  return impl_->options.token;
}

void WebServer::Run() {
  impl_->io.run();
}

void WebServer::Stop() {
  net::post(impl_->io, [this] {
    boost::system::error_code ec;
    impl_->acceptor.close(ec);
    impl_->io.stop();
  });
}

WebServer::Stats WebServer::GetStats() const {
  std::lock_guard lock(impl_->stats_mutex);
  return impl_->stats;
}

}  // namespace canfleet::web
