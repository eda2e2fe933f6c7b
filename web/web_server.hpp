#pragma once
/// @file `canfleet web`: an HTTP + WebSocket server (Boost.Beast, Debian's libboost-dev) that serves
/// the page and its assets from the repository's web/static (no CDN: it works offline), the fleet's
/// state as JSON (`GET /api/state`), a stream of updates (`/ws`, a WebSocket: a snapshot, then
/// what changed, every update period), and actions (`POST /api/action`: a control API Request in
/// protobuf's JSON mapping, forwarded to the orchestrator, whose answer and refusal messages are
/// the CLI's).
///
/// Security (web/README.md): bound to 127.0.0.1 by default; bound to any other address, actions
/// need the token printed at start (`Authorization: Bearer <token>`); `read_only` turns them off.
/// Every connection has limits: header and body size, message size, time to send a request,
/// connections at once (more are answered 503 and closed). Nothing a client sends stops the server.
///
/// Threading: its own io_context on the thread that calls Run(); actions run on one worker thread
/// (a control request may take seconds: an SDO transfer), their answers posted back.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include "web/web_state.hpp"

namespace canfleet::web {

struct WebServerOptions {
  std::string address = "127.0.0.1";
  std::uint16_t port = 8080;  ///< 0: any free port (Port() says which)
  std::filesystem::path static_dir;
  /// The orchestrator's control endpoint for actions; empty: read-only.
  std::string control;
  bool read_only = false;
  /// Needed for actions when given, and always when bound beyond loopback (made up at start then).
  std::string token;
  std::size_t max_connections = 256;
  std::chrono::milliseconds update_period{200};
  std::size_t max_body_bytes = 64 * 1024;
  std::size_t max_message_bytes = 4 * 1024;  ///< WebSocket messages from the page (it sends none)
  std::chrono::seconds request_timeout{15};  ///< to send a whole request, or for a write to drain
};

/// Whether `address` is a loopback address (127.0.0.0/8, ::1).
bool IsLoopback(const std::string& address);

class WebServer {
 public:
  /// Binds at once (throws std::runtime_error saying why: the address in use, a bad address).
  WebServer(WebState& state, WebServerOptions options);
  ~WebServer();
  WebServer(const WebServer&) = delete;
  WebServer& operator=(const WebServer&) = delete;

  std::uint16_t Port() const;
  /// The page's URL (with the token in its fragment when actions need one).
  std::string Url() const;
  /// Whether actions are on, and whether they need the token.
  bool ActionsEnabled() const;
  const std::string& Token() const;
  /// Serves until Stop() (from any thread).
  void Run();
  void Stop();

  struct Stats {
    std::uint64_t connections = 0, refused = 0, requests = 0, bad_requests = 0, ws_messages = 0, ws_bytes = 0,
                  actions = 0;
  };
  Stats GetStats() const;

  struct Impl;  ///< public for the sessions of web_server.cpp; defined there only

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace canfleet::web
