// ControlServer and ControlClient on a real loopback socket, with a fake ControlHandler: framing,
// ids, pipelining, streams, and what a malformed client or a slow one costs (only its own
// connection). The server runs on its own io thread, as in the orchestrator.
#include <gtest/gtest.h>
#include <poll.h>
#include <stdlib.h>
#include <sys/socket.h>
#include <unistd.h>

#include <asio/executor_work_guard.hpp>
#include <asio/post.hpp>
#include <asio/steady_timer.hpp>
#include <asio/write.hpp>
#include <atomic>
#include <future>
#include <mutex>
#include <thread>

#include "bus/wire/auth_token.hpp"
#include "bus/wire/varint.hpp"
#include "orchestrator/control/control_client.hpp"
#include "orchestrator/control/control_server.hpp"

namespace canfleet::control {
namespace {

using namespace std::chrono_literals;

bool WaitUntil(const std::function<bool()>& condition, std::chrono::milliseconds timeout = 10s) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!condition()) {
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(2ms);
  }
  return true;
}

/// Calls the test's function for each request, on the io thread.
class FakeHandler final : public ControlHandler {
 public:
  using Function = std::function<void(const Request&, std::shared_ptr<Responder>)>;
  void Handle(const Request& request, std::shared_ptr<Responder> responder) override {
    calls++;
    if (on_request) on_request(request, std::move(responder));
  }
  Function on_request;
  std::atomic<int> calls{0};
};

Response StatusResponse(const Request& request, const std::string& topology) {
  Response r;
  r.set_id(request.id());
  r.mutable_status()->set_topology(topology);
  return r;
}

Request StatusRequest() {
  Request r;
  r.mutable_status();
  return r;
}

class ControlTransport : public ::testing::Test {
 protected:
  /// `listen`: 0.0.0.0 is beyond loopback (a token is required); the clients still connect
  /// through 127.0.0.1, which reaches that listener too.
  void Start(ControlServerOptions options = {}, const std::string& listen = "tcp://127.0.0.1:0") {
    server_ = std::make_unique<ControlServer>(io_, handler_, options);
    const auto ep = server_->Listen(listen);
    endpoint_ = "tcp://127.0.0.1:" + std::to_string(ep.port());
    thread_ = std::thread([this] { io_.run(); });
  }

  void TearDown() override {
    if (!server_) return;
    OnIo([this] { server_->Close(); });
    work_.reset();
    thread_.join();
  }

  /// Runs `f` on the io thread and waits for it.
  template <class F>
  auto OnIo(F f) -> decltype(f()) {
    std::packaged_task<decltype(f())()> task(std::move(f));
    auto result = task.get_future();
    asio::post(io_, [&task] { task(); });
    return result.get();
  }

  asio::io_context io_;
  asio::executor_work_guard<asio::io_context::executor_type> work_ = asio::make_work_guard(io_);
  FakeHandler handler_;
  std::unique_ptr<ControlServer> server_;
  std::string endpoint_;
  std::thread thread_;
};

/// A hand-driven TCP connection, for bytes no ControlClient would send.
class RawClient {
 public:
  explicit RawClient(std::uint16_t port) : socket_(io_) {
    socket_.connect(asio::ip::tcp::endpoint(asio::ip::address_v4::loopback(), port));
  }
  void Send(const std::string& bytes) { asio::write(socket_, asio::buffer(bytes)); }
  /// Reads until the server closes the connection; nullopt if it does not within the timeout.
  std::optional<std::string> ReadUntilClosed(std::chrono::milliseconds timeout = 10s) {
    std::string got;
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      const auto left =
          std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0) return std::nullopt;
      pollfd p{socket_.native_handle(), POLLIN, 0};
      if (::poll(&p, 1, static_cast<int>(left.count())) <= 0) continue;
      char buffer[4096];
      const ssize_t n = ::recv(socket_.native_handle(), buffer, sizeof buffer, 0);
      if (n <= 0) return got;
      got.append(buffer, static_cast<std::size_t>(n));
    }
  }

 private:
  asio::io_context io_;
  asio::ip::tcp::socket socket_;
};

std::uint16_t PortOf(const std::string& endpoint) {
  return static_cast<std::uint16_t>(std::stoi(endpoint.substr(endpoint.rfind(':') + 1)));
}

/// The responses in `bytes` (length-delimited).
std::vector<Response> Responses(const std::string& bytes) {
  DelimitedReader reader;
  reader.Append(bytes.data(), bytes.size());
  std::vector<Response> out;
  Response r;
  while (reader.Next(r) == DelimitedReader::Result::kMessage)
    out.push_back(r);
  return out;
}

TEST_F(ControlTransport, ARequestGetsTheResponseWithItsId) {
  handler_.on_request = [](const Request& request, std::shared_ptr<Responder> responder) {
    ASSERT_TRUE(request.has_status());
    responder->Send(StatusResponse(request, "demo"));
  };
  Start();
  ControlClient client(endpoint_);
  const Response first = client.Call(StatusRequest());
  const Response second = client.Call(StatusRequest());
  EXPECT_EQ(first.id(), 1u) << "the client numbers requests from 1";
  EXPECT_EQ(second.id(), 2u);
  EXPECT_EQ(second.status().topology(), "demo");
  EXPECT_EQ(handler_.calls, 2);
}

TEST_F(ControlTransport, ResponsesMayComeLaterAndOutOfOrder) {
  // canfleet_control.proto: "responses may come out of order when requests are pipelined".
  std::vector<std::pair<Request, std::shared_ptr<Responder>>> held;
  handler_.on_request = [&held](const Request& request, std::shared_ptr<Responder> responder) {
    held.emplace_back(request, responder);
    if (held.size() == 2) {
      for (auto it = held.rbegin(); it != held.rend(); ++it)
        it->second->Send(StatusResponse(it->first, "answer to " + std::to_string(it->first.id())));
      held.clear();
    }
  };
  Start();
  ControlClient client(endpoint_);
  Request a = StatusRequest();
  a.set_id(10);
  Request b = StatusRequest();
  b.set_id(20);
  client.Send(a);
  client.Send(b);
  const auto r1 = client.Receive(10s);
  const auto r2 = client.Receive(10s);
  ASSERT_TRUE(r1 && r2);
  EXPECT_EQ(r1->id(), 20u);
  EXPECT_EQ(r1->status().topology(), "answer to 20");
  EXPECT_EQ(r2->id(), 10u);
}

TEST_F(ControlTransport, CallSetsOtherResponsesAsideForReceive) {
  std::shared_ptr<Responder> first;
  Request first_request;
  handler_.on_request = [&](const Request& request, std::shared_ptr<Responder> responder) {
    if (!first) {
      first = responder;
      first_request = request;
      return;
    }
    first->Send(StatusResponse(first_request, "late"));  // before the answer Call waits for
    responder->Send(StatusResponse(request, "now"));
  };
  Start();
  ControlClient client(endpoint_);
  client.Send(StatusRequest());
  EXPECT_EQ(client.Call(StatusRequest()).status().topology(), "now");
  const auto late = client.Receive(0ms);
  ASSERT_TRUE(late.has_value());
  EXPECT_EQ(late->status().topology(), "late");
}

TEST_F(ControlTransport, ARequestWithoutBodyIsAnsweredWithoutTheHandler) {
  Start();
  ControlClient client(endpoint_);
  Request empty;
  empty.set_id(5);
  const Response r = client.Call(empty);
  EXPECT_EQ(r.id(), 5u);
  EXPECT_EQ(r.error(), "request 5 has no body this orchestrator knows (a newer client?)");
  EXPECT_EQ(handler_.calls, 0);
}

TEST_F(ControlTransport, AHandlerExceptionBecomesAnErrorResponse) {
  handler_.on_request = [](const Request&, std::shared_ptr<Responder>) { throw std::runtime_error("boom"); };
  Start();
  ControlClient client(endpoint_);
  EXPECT_EQ(client.Call(StatusRequest()).error(), "internal error: boom");
  EXPECT_EQ(client.Call(StatusRequest()).error(), "internal error: boom") << "the connection survives";
}

TEST_F(ControlTransport, MalformedOrOversizedMessagesCloseOnlyThatConnection) {
  handler_.on_request = [](const Request& request, std::shared_ptr<Responder> responder) {
    responder->Send(StatusResponse(request, "demo"));
  };
  Start();
  ControlClient good(endpoint_);
  ASSERT_EQ(good.Call(StatusRequest()).status().topology(), "demo");

  std::string two_mib(10, '\0');
  two_mib.resize(
      static_cast<std::size_t>(wire::WriteVarint(2u << 20, reinterpret_cast<std::uint8_t*>(two_mib.data())) -
                               reinterpret_cast<std::uint8_t*>(two_mib.data())));
  const std::pair<std::string, std::string> kBad[] = {
      {std::string(11, '\xFF'), "protocol error: malformed length prefix (varint longer than 10 bytes)"},
      {two_mib, "protocol error: message of 2097152 bytes exceeds the limit of 1048576"},
      {std::string("\x03\xFF\xFF\xFF", 4),
       "protocol error: a message of 3 bytes does not parse as canfleet.control.Request"},
  };
  for (const auto& [bytes, error] : kBad) {
    RawClient bad(PortOf(endpoint_));
    bad.Send(bytes);
    const auto got = bad.ReadUntilClosed();
    ASSERT_TRUE(got.has_value()) << "the server closes the connection";
    const auto responses = Responses(*got);
    ASSERT_EQ(responses.size(), 1u) << "one error response, then the close";
    EXPECT_EQ(responses[0].id(), 0u);
    EXPECT_EQ(responses[0].error(), error);
    EXPECT_EQ(good.Call(StatusRequest()).status().topology(), "demo") << "other clients carry on";
  }
  EXPECT_EQ(OnIo([this] { return server_->Stats().protocol_errors; }), 3u);
  EXPECT_EQ(OnIo([this] { return server_->SessionCount(); }), 1u);
}

TEST_F(ControlTransport, CallReportsTheServersLastWordOnAConnection) {
  // A response of id 0 with an error is what the server sends before it closes a connection.
  handler_.on_request = [](const Request&, std::shared_ptr<Responder> responder) {
    Response r;
    r.set_error("protocol error: something");
    responder->Send(r);
  };
  Start();
  ControlClient client(endpoint_);
  try {
    client.Call(StatusRequest());
    ADD_FAILURE() << "no error";
  } catch (const ControlError& e) {
    EXPECT_EQ(std::string(e.what()),
              "the orchestrator at " + endpoint_ + " refused the request: protocol error: something");
  }
}

TEST_F(ControlTransport, ARequestOverTheLimitIsRefusedByTheClient) {
  Start();
  ControlClient client(endpoint_);
  Request huge;
  huge.mutable_io_set()->set_value(std::string(kMaxControlMessage + 1, 'x'));
  EXPECT_THROW(client.Call(huge), ControlError);
  EXPECT_EQ(handler_.calls, 0);
}

TEST_F(ControlTransport, ADumpStreamStopsWhenTheClientCloses) {
  std::atomic<bool> on_close_ran{false};
  std::atomic<bool> stream_stopped{false};
  std::atomic<int> batches{0};
  std::shared_ptr<asio::steady_timer> timer;
  std::function<void(std::shared_ptr<Responder>, std::uint64_t)> tick;
  tick = [&](std::shared_ptr<Responder> responder, std::uint64_t id) {
    if (responder->Closed()) {
      stream_stopped = true;
      return;
    }
    Response r;
    r.set_id(id);
    auto* frame = r.mutable_frames()->add_frames();
    frame->set_bus("can0");
    frame->set_id(0x185);
    responder->Send(r);
    batches++;
    timer->expires_after(1ms);
    timer->async_wait([&tick, responder, id](const asio::error_code& ec) {
      if (!ec) tick(responder, id);
    });
  };
  handler_.on_request = [&](const Request& request, std::shared_ptr<Responder> responder) {
    ASSERT_TRUE(request.has_dump());
    responder->OnClose([&on_close_ran] { on_close_ran = true; });
    timer = std::make_shared<asio::steady_timer>(io_);
    tick(responder, request.id());
  };
  Start();
  {
    ControlClient client(endpoint_);
    Request dump;
    dump.mutable_dump()->set_bus("can0");
    const std::uint64_t id = client.Send(dump);
    for (int i = 0; i < 3; ++i) {
      const auto r = client.Receive(10s);
      ASSERT_TRUE(r.has_value());
      EXPECT_EQ(r->id(), id) << "every batch carries the dump request's id";
      ASSERT_EQ(r->frames().frames_size(), 1);
      EXPECT_EQ(r->frames().frames(0).id(), 0x185u);
    }
    EXPECT_FALSE(on_close_ran);
  }  // the client closes
  EXPECT_TRUE(WaitUntil([&] { return on_close_ran.load(); })) << "OnClose runs when the client goes";
  EXPECT_TRUE(WaitUntil([&] { return stream_stopped.load(); })) << "the stream sees Closed() and stops";
  const int sent = batches;
  std::this_thread::sleep_for(20ms);
  EXPECT_EQ(batches, sent);
  OnIo([&] { timer.reset(); });
}

TEST_F(ControlTransport, OnCloseAfterTheCloseRunsAtOnceAndSendIsIgnored) {
  std::shared_ptr<Responder> kept;
  handler_.on_request = [&](const Request&, std::shared_ptr<Responder> responder) { kept = responder; };
  Start();
  {
    ControlClient client(endpoint_);
    client.Send(StatusRequest());
    ASSERT_TRUE(WaitUntil([&] { return handler_.calls == 1; }));
  }
  ASSERT_TRUE(WaitUntil([&] { return OnIo([&] { return kept->Closed(); }); }));
  EXPECT_TRUE(OnIo([&] {
    bool ran = false;
    kept->OnClose([&ran] { ran = true; });
    kept->Send(StatusResponse(StatusRequest(), "nobody"));  // ignored
    return ran;
  }));
  OnIo([&] { kept.reset(); });
}

TEST_F(ControlTransport, ServerCloseEndsTheConnectionsAfterWhatWasQueued) {
  // A Shutdown's Done is sent before the fleet manager closes the server: it must still arrive.
  std::atomic<bool> on_close_ran{false};
  handler_.on_request = [&](const Request& request, std::shared_ptr<Responder> responder) {
    responder->OnClose([&on_close_ran] { on_close_ran = true; });
    Response done;
    done.set_id(request.id());
    done.mutable_done()->set_detail("stopping");
    responder->Send(done);
    server_->Close();
  };
  Start();
  ControlClient client(endpoint_);
  Request shutdown;
  shutdown.mutable_shutdown();
  EXPECT_EQ(client.Call(shutdown).done().detail(), "stopping");
  // The Done may leave (asio writes speculatively) before Handle even returns.
  EXPECT_TRUE(WaitUntil([&] { return on_close_ran.load(); }));
  try {
    client.Receive(10s);
    ADD_FAILURE() << "the connection stayed open";
  } catch (const ControlError& e) {
    EXPECT_EQ(std::string(e.what()), "the orchestrator at " + endpoint_ + " closed the connection");
  }
  EXPECT_THROW(ControlClient{endpoint_}, ControlError) << "no longer accepting";
}

TEST_F(ControlTransport, FrameBatchesBeyondTheBacklogAreDroppedOtherResponsesAreNot) {
  handler_.on_request = [](const Request& request, std::shared_ptr<Responder> responder) {
    Response batch;
    batch.set_id(request.id());
    batch.mutable_frames()->add_frames()->set_id(1);
    // The first goes out at once, the second waits for it, the third finds the backlog full.
    for (int i = 0; i < 3; ++i)
      responder->Send(batch);
    Response done;
    done.set_id(request.id());
    done.mutable_done();
    responder->Send(done);
  };
  ControlServerOptions options;
  options.max_backlog_bytes = 1;
  Start(options);
  ControlClient client(endpoint_);
  Request dump;
  dump.mutable_dump();
  client.Send(dump);
  std::vector<Response> got;
  while (got.empty() || !got.back().has_done()) {
    auto r = client.Receive(10s);
    ASSERT_TRUE(r.has_value());
    got.push_back(*r);
  }
  EXPECT_EQ(got.size(), 3u);
  EXPECT_EQ(OnIo([this] { return server_->Stats().dropped_batches; }), 1u);
}

TEST_F(ControlTransport, AResponseOverTheLimitBecomesAnError) {
  handler_.on_request = [](const Request& request, std::shared_ptr<Responder> responder) {
    Response r = StatusResponse(request, std::string(kMaxControlMessage, 'x'));
    responder->Send(r);
  };
  Start();
  ControlClient client(endpoint_);
  const Response r = client.Call(StatusRequest());
  EXPECT_EQ(r.error().substr(0, 24), "response too large (1048") << r.error();
}

TEST_F(ControlTransport, ACallWithoutAnswerTimesOut) {
  std::shared_ptr<Responder> never;
  handler_.on_request = [&never](const Request&, std::shared_ptr<Responder> responder) { never = responder; };
  Start();
  ControlClient client(endpoint_);
  try {
    client.Call(StatusRequest(), 100ms);
    ADD_FAILURE() << "answered";
  } catch (const ControlError& e) {
    EXPECT_EQ(std::string(e.what()), "no response from the orchestrator at " + endpoint_ + " within 100ms");
  }
  OnIo([&never] { never.reset(); });
}

TEST(ControlClient, NobodyListeningSaysSoAndSuggestsCanfleetUp) {
  asio::io_context io;
  asio::ip::tcp::acceptor probe(io, asio::ip::tcp::endpoint(asio::ip::address_v4::loopback(), 0));
  const std::string endpoint = "tcp://127.0.0.1:" + std::to_string(probe.local_endpoint().port());
  probe.close();
  try {
    ControlClient client(endpoint);
    ADD_FAILURE() << "connected";
  } catch (const ControlError& e) {
    EXPECT_EQ(std::string(e.what()), "no orchestrator at " + endpoint + " (is `canfleet up` running?)");
  }
}

TEST(ControlClient, MalformedEndpointsAreRefused) {
  EXPECT_THROW(ControlClient("127.0.0.1:29700"), std::invalid_argument);
  try {
    ControlClient client("unix:///tmp/x.sock");
    ADD_FAILURE() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("TCP only"), std::string::npos) << e.what();
  }
}

TEST(ControlServer, ListensOnLoopbackByDefaultAndRefusesMalformedEndpoints) {
  asio::io_context io;
  FakeHandler handler;
  ControlServer server(io, handler);
  const auto ep = server.Listen("tcp://127.0.0.1:0");
  EXPECT_TRUE(ep.address().is_loopback());
  EXPECT_NE(ep.port(), 0);
  EXPECT_THROW(server.Listen("tcp://127.0.0.1"), std::invalid_argument);
  EXPECT_THROW(server.Listen("unix:///tmp/control.sock"), std::invalid_argument);
  EXPECT_THROW(server.Listen("tcp://127.0.0.1:" + std::to_string(ep.port())), std::system_error) << "in use";
}

TEST(DelimitedReader, MessagesSplitAcrossReadsAndManyInOneRead) {
  std::string stream;
  for (int i = 1; i <= 3; ++i) {
    Request r = StatusRequest();
    r.set_id(static_cast<std::uint64_t>(i));
    ASSERT_TRUE(AppendDelimited(r, stream));
  }
  DelimitedReader reader;
  std::vector<std::uint64_t> ids;
  Request r;
  for (const char c : stream) {  // one byte at a time
    reader.Append(&c, 1);
    while (reader.Next(r) == DelimitedReader::Result::kMessage)
      ids.push_back(r.id());
  }
  EXPECT_EQ(ids, (std::vector<std::uint64_t>{1, 2, 3}));
  EXPECT_EQ(reader.Buffered(), 0u);
}

// ---- the fleet's token (bus/wire/auth_gate.hpp) -------------------------------------------------

constexpr const char* kToken = "fleet-token-0123456789abcdef";

/// Sets CANFLEET_TOKEN for the ControlClients of one test (they read the environment).
class ClientToken {
 public:
  explicit ClientToken(const char* token) {
    ::unsetenv("CANFLEET_TOKEN_FILE");
    if (token)
      ::setenv("CANFLEET_TOKEN", token, 1);
    else
      ::unsetenv("CANFLEET_TOKEN");
  }
  ~ClientToken() { ::unsetenv("CANFLEET_TOKEN"); }
};

void AnswerStatus(FakeHandler& handler) {
  handler.on_request = [](const Request& request, std::shared_ptr<Responder> responder) {
    responder->Send(StatusResponse(request, "ok"));
  };
}

std::string CallError(const std::string& endpoint) {
  try {
    ControlClient client(endpoint);
    client.Call(StatusRequest(), 5s);
  } catch (const ControlError& e) {
    return e.what();
  }
  return "answered";
}

TEST_F(ControlTransport, BeyondLoopbackWithoutATokenTheServerDoesNotStart) {
  server_ = std::make_unique<ControlServer>(io_, handler_, ControlServerOptions{});
  try {
    server_->Listen("tcp://0.0.0.0:0");
    FAIL() << "listened beyond loopback without a token";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("needs the fleet's token"), std::string::npos) << e.what();
  }
  server_.reset();
}

TEST_F(ControlTransport, BeyondLoopbackAClientWithoutTheTokenIsRefusedAndTold) {
  AnswerStatus(handler_);
  Start({.token = kToken}, "tcp://0.0.0.0:0");
  ClientToken none(nullptr);
  const auto error = CallError(endpoint_);
  EXPECT_NE(error.find("refused: no token"), std::string::npos) << error;
  EXPECT_EQ(handler_.calls, 0);
  EXPECT_TRUE(WaitUntil([&] { return OnIo([&] { return server_->Stats().refused; }) == 1; }));
  EXPECT_EQ(OnIo([&] { return server_->SessionCount(); }), 0u);
}

TEST_F(ControlTransport, BeyondLoopbackAWrongTokenIsRefused) {
  AnswerStatus(handler_);
  Start({.token = kToken}, "tcp://0.0.0.0:0");
  ClientToken wrong("fleet-token-0123456789abcdeX");
  const auto error = CallError(endpoint_);
  EXPECT_NE(error.find("refused: wrong token"), std::string::npos) << error;
  EXPECT_EQ(handler_.calls, 0);
}

TEST_F(ControlTransport, BeyondLoopbackTheRightTokenIsLetIn) {
  AnswerStatus(handler_);
  Start({.token = kToken}, "tcp://0.0.0.0:0");
  ClientToken right(kToken);
  EXPECT_EQ(CallError(endpoint_), "answered");
  EXPECT_EQ(handler_.calls, 1);
}

TEST_F(ControlTransport, OnLoopbackNoTokenIsNeededAndOneIsTaken) {
  AnswerStatus(handler_);
  Start();
  {
    ClientToken none(nullptr);
    EXPECT_EQ(CallError(endpoint_), "answered");
  }
  ClientToken some(kToken);  // a client with a token talks to a server that asks for none
  EXPECT_EQ(CallError(endpoint_), "answered");
  EXPECT_EQ(handler_.calls, 2);
}

TEST_F(ControlTransport, OnLoopbackAServerWithATokenStillRefusesAWrongOne) {
  AnswerStatus(handler_);
  Start({.token = kToken});
  ClientToken wrong("fleet-token-0123456789abcdeX");
  EXPECT_NE(CallError(endpoint_).find("wrong token"), std::string::npos);
}

TEST_F(ControlTransport, APreambleInPiecesIsReadWhole) {
  AnswerStatus(handler_);
  Start({.token = kToken}, "tcp://0.0.0.0:0");
  RawClient raw(PortOf(endpoint_));
  const std::string preamble = wire::EncodeAuthPreamble(kToken);
  raw.Send(preamble.substr(0, 3));
  std::this_thread::sleep_for(20ms);  // not a timing assertion: only makes the pieces arrive apart
  raw.Send(preamble.substr(3, 10));
  std::this_thread::sleep_for(20ms);
  std::string request;
  ASSERT_TRUE(AppendDelimited(
      [] {
        Request r = StatusRequest();
        r.set_id(7);
        return r;
      }(),
      request));
  raw.Send(preamble.substr(13) + request);
  ASSERT_TRUE(WaitUntil([&] { return handler_.calls == 1; }));
}

TEST_F(ControlTransport, AClientThatSaysNothingIsClosedAfterTheHandshakeTimeout) {
  Start({.token = kToken, .handshake_timeout = 100ms}, "tcp://0.0.0.0:0");
  RawClient raw(PortOf(endpoint_));
  const auto got = raw.ReadUntilClosed();
  ASSERT_TRUE(got.has_value()) << "still open";
  const auto responses = Responses(*got);
  ASSERT_EQ(responses.size(), 1u);
  EXPECT_NE(responses[0].error().find("nothing received within 100 ms"), std::string::npos);
  EXPECT_EQ(OnIo([&] { return server_->GateStats().timed_out; }), 1u);
}

TEST_F(ControlTransport, OnLoopbackAClientThatSaysNothingYetBecomesASession) {
  // The Python clock connects first and speaks at the test's first step: no token needed on
  // loopback, so silence is no reason to refuse; the session counts against max_sessions.
  Start({.handshake_timeout = 100ms});
  RawClient raw(PortOf(endpoint_));
  ASSERT_TRUE(WaitUntil([&] { return OnIo([&] { return server_->SessionCount(); }) == 1; }));
  EXPECT_EQ(OnIo([&] { return server_->GateStats().timed_out; }), 1u);
}

TEST_F(ControlTransport, ConnectionsWaitingAtTheGateAreBounded) {
  Start({.token = kToken, .max_pending = 2}, "tcp://0.0.0.0:0");
  RawClient a(PortOf(endpoint_)), b(PortOf(endpoint_));
  ASSERT_TRUE(WaitUntil([&] { return OnIo([&] { return server_->GateStats().pending; }) == 2; }));
  RawClient c(PortOf(endpoint_));
  const auto got = c.ReadUntilClosed();
  ASSERT_TRUE(got.has_value()) << "a third silent connection was kept";
  EXPECT_EQ(OnIo([&] { return server_->GateStats().pending; }), 2u);
}

TEST_F(ControlTransport, SessionsAreBoundedAndTheNextClientIsTold) {
  AnswerStatus(handler_);
  Start({.max_sessions = 2});
  ClientToken none(nullptr);
  ControlClient first(endpoint_), second(endpoint_);
  first.Call(StatusRequest(), 5s);
  second.Call(StatusRequest(), 5s);
  const auto error = CallError(endpoint_);
  EXPECT_NE(error.find("too many connections"), std::string::npos) << error;
  EXPECT_EQ(OnIo([&] { return server_->SessionCount(); }), 2u);
}

TEST_F(ControlTransport, AMessageBegunAndNeverFinishedClosesTheConnection) {
  // Issue 32: a length prefix of 1000 bytes and 10 of them, then nothing: the connection may not
  // hold what it sent (up to the 1 MiB limit) for as long as it likes.
  Start({.message_timeout = 100ms});
  RawClient raw(PortOf(endpoint_));
  raw.Send(std::string("\xE8\x07", 2) + std::string(10, 'x'));
  const auto got = raw.ReadUntilClosed();
  ASSERT_TRUE(got.has_value()) << "still open";
  const auto responses = Responses(*got);
  ASSERT_EQ(responses.size(), 1u);
  EXPECT_NE(responses[0].error().find("still incomplete (12 bytes)"), std::string::npos)
      << responses[0].error();
}

}  // namespace
}  // namespace canfleet::control
