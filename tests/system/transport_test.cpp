// BrokerServer and BrokerClientPort in one process, over real sockets on one io_context (issue 4,
// "Node <-> broker protocol"): batching, controller events, reconnection, refusals, deadlines,
// and the lifetime rules of style.md ("Asio lifetimes").
#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <asio/io_context.hpp>
#include <atomic>
#include <memory>
#include <optional>
#include <sstream>
#include <thread>

#include "bus/broker_client/broker_client_port.hpp"
#include "bus/wire/message_writer.hpp"
#include "bus/wire/stream_decoder.hpp"
#include "clock/asio_scheduler.hpp"
#include "orchestrator/broker/broker.hpp"
#include "orchestrator/transport/broker_server.hpp"
#include "tests/support/wire_text.hpp"
#include "tests/system/support/child_process.hpp"

namespace canfleet::system_test {
namespace {

using namespace std::chrono_literals;

/// Captures spdlog output for the duration of a test.
class LogCapture {
 public:
  LogCapture() : previous_(spdlog::default_logger()) {
    auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(stream_);
    spdlog::set_default_logger(std::make_shared<spdlog::logger>("capture", sink));
    spdlog::set_level(spdlog::level::debug);
  }
  ~LogCapture() { spdlog::set_default_logger(previous_); }
  std::string Text() const { return stream_.str(); }

 private:
  std::ostringstream stream_;
  std::shared_ptr<spdlog::logger> previous_;
};

class Transport : public ::testing::Test {
 protected:
  Transport() { broker_.AddBus({.name = "can0", .bitrate = 1'000'000, .paced = true}); }

  /// Runs the io_context until `condition` holds (or the patience runs out).
  bool RunUntil(const std::function<bool()>& condition, std::chrono::milliseconds timeout = kPatience) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (!condition()) {
      if (std::chrono::steady_clock::now() >= deadline) return false;
      io_.restart();
      io_.run_for(5ms);
    }
    return true;
  }

  std::string Listen(transport::BrokerServer& server) {
    return server.Listen(wire::Endpoint::Parse("unix://" + dir_.File("t.sock"))).ToString();
  }

  std::unique_ptr<BrokerClientPort> Client(const std::string& endpoint, const std::string& name,
                                           const std::string& bus = "can0") {
    BrokerClientOptions options;
    options.endpoint = endpoint;
    options.bus = bus;
    options.node_name = name;
    return std::make_unique<BrokerClientPort>(io_, options);
  }

  /// Two clients, "a" and "b", attached to a new unpaced bus "fast" of `server`.
  std::pair<std::unique_ptr<BrokerClientPort>, std::unique_ptr<BrokerClientPort>> ConnectedPair(
      transport::BrokerServer& server) {
    broker_.AddBus({.name = "fast", .bitrate = 1'000'000, .paced = false});
    const std::string ep = Listen(server);
    auto a = Client(ep, "a", "fast");
    auto b = Client(ep, "b", "fast");
    EXPECT_TRUE(RunUntil([&] { return a->Connected() && b->Connected(); }));
    return {std::move(a), std::move(b)};
  }

  TempDir dir_;
  asio::io_context io_;
  AsioScheduler scheduler_{io_};
  broker::Broker broker_{scheduler_};
};

TEST_F(Transport, ManySendsInOneTurnLeaveInOneWrite) {
  // "Send() appends to an outgoing batch flushed once per io_context turn": 1000 frames sent from
  // one handler are one socket write.
  transport::BrokerServer server(io_, broker_);
  auto [a, b] = ConnectedPair(server);
  ASSERT_TRUE(a->Connected() && b->Connected());
  std::vector<std::pair<CanFrame, BusTime>> got;
  b->OnReceive([&](const CanFrame& f, BusTime t) { got.emplace_back(f, t); });
  ASSERT_TRUE(RunUntil([&] { return a->Stats().writes >= 1; }));  // the Hello has left
  const auto writes_before = a->Stats().writes;
  asio::post(io_, [&] {
    for (std::uint32_t i = 0; i < 1000; ++i)
      ASSERT_TRUE(a->Send(CanFrame::Data(0x100 + (i % 16), {std::uint8_t(i), std::uint8_t(i >> 8)})));
  });
  ASSERT_TRUE(RunUntil([&] { return got.size() >= 1000; })) << got.size();
  EXPECT_EQ(a->Stats().writes - writes_before, 1u);
  for (std::size_t i = 0; i < got.size(); ++i) {
    ASSERT_EQ(got[i].first.data[0] | got[i].first.data[1] << 8, static_cast<int>(i));
    if (i > 0) {
      ASSERT_GE(got[i].second, got[i - 1].second);
    }
  }
}

TEST_F(Transport, SocketsAreReadOnlyWhenDataWaits) {
  // bus/wire/socket_io.hpp: a connection reads until a read comes back short, then waits for
  // readiness. Asio's async_read_some re-read after every completion and found the socket empty:
  // then half of all reads returned EAGAIN. 300 batches, one per io_context turn, each waiting for
  // its delivery, must cost (nearly) no empty reads on either side.
  transport::BrokerServer server(io_, broker_);
  auto [a, b] = ConnectedPair(server);
  ASSERT_TRUE(a->Connected() && b->Connected());
  std::size_t got = 0;
  b->OnReceive([&](const CanFrame&, BusTime) { ++got; });
  const auto server_before = server.Stats();
  const auto b_before = b->Stats();
  constexpr std::size_t kBatches = 300;
  for (std::size_t i = 0; i < kBatches; ++i) {
    ASSERT_TRUE(a->Send(CanFrame::Data(0x181, {std::uint8_t(i)})));
    ASSERT_TRUE(RunUntil([&] { return got == i + 1; })) << i;
  }
  const auto server_reads = server.Stats().reads - server_before.reads;
  const auto server_empty = server.Stats().empty_reads - server_before.empty_reads;
  const auto b_reads = b->Stats().reads - b_before.reads;
  const auto b_empty = b->Stats().empty_reads - b_before.empty_reads;
  EXPECT_GE(server_reads, kBatches);
  EXPECT_LE(server_empty * 10, server_reads) << server_empty << " of " << server_reads;
  EXPECT_GE(b_reads, kBatches);
  EXPECT_LE(b_empty * 10, b_reads) << b_empty << " of " << b_reads;
  // Deliveries leave straight from the round's shared encoding, not copied per session.
  EXPECT_GE(server.Stats().gathered_writes - server_before.gathered_writes, kBatches);
}

TEST_F(Transport, ControllerEventsReachTheNode) {
  // A node alone on a paced bus gets ACK errors and goes error-passive (ISO 11898-1 §12.1.4,
  // rule 3 exception 1); the event reaches OnStateChange and State(). Over TCP.
  transport::BrokerServer server(io_, broker_);
  const wire::Endpoint tcp = server.Listen(wire::Endpoint::Parse("tcp://127.0.0.1:0"));
  ASSERT_NE(tcp.port, 0);
  auto a = Client(tcp.ToString(), "alone");
  std::vector<ControllerEvent> events;
  a->OnStateChange([&](const ControllerEvent& e) { events.push_back(e); });
  ASSERT_TRUE(RunUntil([&] { return a->Connected(); }));
  ASSERT_TRUE(a->Send(CanFrame::Data(0x181, {1})));
  ASSERT_TRUE(RunUntil([&] { return !events.empty(); }));
  EXPECT_EQ(events[0].state, ControllerState::kErrorPassive);
  EXPECT_EQ(events[0].tec, 128);
  EXPECT_EQ(a->State(), ControllerState::kErrorPassive);
}

TEST_F(Transport, SendFailsWhileNoBrokerListens) {
  // An unplugged cable: frames are refused, attempts keep failing, nothing crashes.
  LogCapture log;
  auto a = Client("unix://" + dir_.File("nobody.sock"), "a");
  EXPECT_FALSE(a->Send(CanFrame::Data(0x181, {1})));
  ASSERT_TRUE(RunUntil([&] { return a->Stats().failed_attempts >= 2; }));
  EXPECT_FALSE(a->Connected());
  EXPECT_FALSE(a->Session());
  EXPECT_FALSE(a->Send(CanFrame::Data(0x181, {1})));
  EXPECT_NE(log.Text().find("retrying in 200 ms"), std::string::npos) << log.Text();
}

TEST_F(Transport, ReconnectsToANewServerAndIsANewController) {
  auto server = std::make_unique<transport::BrokerServer>(io_, broker_);
  const std::string ep = Listen(*server);
  auto a = Client(ep, "a");
  std::vector<std::string> connection;
  a->OnConnection(
      [&](bool up, const std::string& detail) { connection.push_back((up ? "up " : "down ") + detail); });
  ASSERT_TRUE(RunUntil([&] { return a->Connected(); }));
  const auto first_port = a->Session()->port_id;
  EXPECT_EQ(broker_.Ports("can0").size(), 1u);

  server.reset();  // the broker goes away: the port is detached, the client told why
  EXPECT_EQ(broker_.Ports("can0").size(), 0u);
  ASSERT_TRUE(RunUntil([&] { return connection.size() == 2; }));
  EXPECT_EQ(connection[1], "down the broker closed the connection: broker shutting down");
  EXPECT_FALSE(a->Send(CanFrame::Data(0x181, {1})));

  server = std::make_unique<transport::BrokerServer>(io_, broker_);
  Listen(*server);
  ASSERT_TRUE(RunUntil([&] { return connection.size() == 3; }));
  EXPECT_TRUE(connection[2].starts_with("up unix://")) << connection[2];
  EXPECT_NE(a->Session()->port_id, first_port);
  EXPECT_EQ(a->Stats().connects, 2u);
  EXPECT_EQ(a->Stats().disconnects, 1u);
}

TEST_F(Transport, RefusalIsLoggedOnBothSides) {
  LogCapture log;
  transport::BrokerServer server(io_, broker_);
  auto a = Client(Listen(server), "a", "nosuch");
  std::vector<std::string> connection;
  a->OnConnection(
      [&](bool up, const std::string& detail) { connection.push_back((up ? "up " : "down ") + detail); });
  ASSERT_TRUE(RunUntil([&] { return server.Stats().refused >= 1 && !connection.empty(); }));
  // The node process is told, so it can give up.
  EXPECT_EQ(connection[0], "down refused: unknown bus nosuch (this broker has: can0)");
  const std::string text = log.Text();
  // The broker's side...
  EXPECT_NE(text.find("closed: refused: unknown bus nosuch (this broker has: can0)"), std::string::npos)
      << text;
  // ...and the node's.
  EXPECT_NE(text.find("refused bus nosuch: unknown bus nosuch (this broker has: can0)"), std::string::npos)
      << text;
  EXPECT_FALSE(a->Connected());
}

// The fleet's token on a broker beyond loopback (bus/wire/auth_gate.hpp): the listener is
// 0.0.0.0, reached here through 127.0.0.1.
constexpr const char* kFleetToken = "fleet-token-0123456789abcdef";

TEST_F(Transport, BeyondLoopbackANodeWithoutTheTokenIsRefusedAndTold) {
  LogCapture log;
  transport::BrokerServer server(io_, broker_, {.token = kFleetToken});
  const auto bound = server.Listen(wire::Endpoint::Parse("tcp://0.0.0.0:0"));
  BrokerClientOptions options;
  options.endpoint = "tcp://127.0.0.1:" + std::to_string(bound.port);
  options.node_name = "intruder";
  auto a = std::make_unique<BrokerClientPort>(io_, options);
  std::vector<std::string> connection;
  a->OnConnection(
      [&](bool up, const std::string& detail) { connection.push_back((up ? "up " : "down ") + detail); });
  ASSERT_TRUE(RunUntil([&] { return !connection.empty(); }));
  EXPECT_NE(connection[0].find("down refused: no token"), std::string::npos) << connection[0];
  EXPECT_EQ(server.SessionCount(), 0u);  // no session was ever made for it
  EXPECT_GE(server.Stats().refused_connections, 1u);
  EXPECT_NE(log.Text().find("refused tcp 127.0.0.1:"), std::string::npos) << log.Text();
}

TEST_F(Transport, BeyondLoopbackAWrongTokenIsRefusedAndTheRightOneAttaches) {
  transport::BrokerServer server(io_, broker_, {.token = kFleetToken});
  const auto bound = server.Listen(wire::Endpoint::Parse("tcp://0.0.0.0:0"));
  BrokerClientOptions options;
  options.endpoint = "tcp://127.0.0.1:" + std::to_string(bound.port);
  options.node_name = "wrong";
  options.token = "fleet-token-0123456789abcdeX";
  auto wrong = std::make_unique<BrokerClientPort>(io_, options);
  std::vector<std::string> connection;
  wrong->OnConnection(
      [&](bool up, const std::string& detail) { connection.push_back((up ? "up " : "down ") + detail); });
  ASSERT_TRUE(RunUntil([&] { return !connection.empty(); }));
  EXPECT_EQ(connection[0], "down refused: wrong token");
  wrong.reset();
  options.node_name = "right";
  options.token = kFleetToken;
  auto right = std::make_unique<BrokerClientPort>(io_, options);
  ASSERT_TRUE(RunUntil([&] { return right->Connected(); }));
}

TEST_F(Transport, BeyondLoopbackWithoutATokenTheBrokerDoesNotListen) {
  transport::BrokerServer server(io_, broker_);
  EXPECT_THROW(server.Listen(wire::Endpoint::Parse("tcp://0.0.0.0:0")), std::runtime_error);
}

TEST_F(Transport, SessionsBeyondTheLimitAreRefusedWithTheReason) {
  // Issue 32: connections are bounded per endpoint; one more is told why in its HelloReply.
  transport::BrokerServer server(io_, broker_, {.max_sessions = 1});
  const std::string ep = Listen(server);
  auto first = Client(ep, "first");
  ASSERT_TRUE(RunUntil([&] { return first->Connected(); }));
  auto second = Client(ep, "second");
  std::vector<std::string> connection;
  second->OnConnection(
      [&](bool up, const std::string& detail) { connection.push_back((up ? "up " : "down ") + detail); });
  ASSERT_TRUE(RunUntil([&] { return !connection.empty(); }));
  EXPECT_EQ(connection[0], "down refused: too many connections to this broker (limit 1)");
  EXPECT_EQ(server.SessionCount(), 1u);
}

TEST_F(Transport, ConnectionWithoutHelloIsClosedAfterTheDeadline) {
  transport::BrokerServer server(io_, broker_, {.hello_timeout = 200ms});
  const std::string ep = Listen(server);
  RawConnection::ReadResult got;
  std::atomic<bool> done = false;  // the peer saw the close (or gave up): `got` is complete
  std::thread peer([&] {
    RawConnection raw(ep);
    got = raw.ReadUntilClosed();
    done = true;
  });
  // The io_context must keep running until the peer is done: the Error message and the close
  // happen in handlers after the session has left the server.
  ASSERT_TRUE(RunUntil([&] { return done.load(); }));
  peer.join();
  EXPECT_TRUE(got.closed);
  EXPECT_EQ(server.Stats().protocol_errors, 1u);
  EXPECT_EQ(server.SessionCount(), 0u);
  wire::StreamDecoder d;
  d.Feed(got.bytes);
  wire::Message m;
  ASSERT_EQ(d.Next(m), wire::StreamDecoder::Result::kMessage);
  EXPECT_EQ(m.envelope.error().reason(), "no Hello within 200 ms");
}

TEST_F(Transport, DisconnectDetachesThePort) {
  transport::BrokerServer server(io_, broker_);
  const std::string ep = Listen(server);
  auto a = Client(ep, "a");
  auto b = Client(ep, "b");
  ASSERT_TRUE(RunUntil([&] { return a->Connected() && b->Connected(); }));
  EXPECT_EQ(broker_.Ports("can0").size(), 2u);
  a.reset();
  ASSERT_TRUE(RunUntil([&] { return broker_.Ports("can0").size() == 1 && server.SessionCount() == 1; }));
  EXPECT_EQ(broker_.Ports("can0")[0].name, "b");
}

TEST_F(Transport, AHandlerMayDestroyItsPort) {
  // "a handler may destroy the port": the rest of the batch is dropped, nothing is touched after.
  transport::BrokerServer server(io_, broker_);
  const std::string ep = Listen(server);
  auto a = Client(ep, "a");
  auto b = Client(ep, "b");
  int calls = 0;
  b->OnReceive([&](const CanFrame&, BusTime) {
    ++calls;
    b.reset();
  });
  ASSERT_TRUE(RunUntil([&] { return a->Connected() && b && b->Connected(); }));
  for (int i = 0; i < 10; ++i)
    a->Send(CanFrame::Data(0x181, {std::uint8_t(i)}));
  ASSERT_TRUE(RunUntil([&] { return b == nullptr; }));
  ASSERT_TRUE(RunUntil([&] { return broker_.Ports("can0").size() == 1; }));
  EXPECT_EQ(calls, 1);
}

TEST_F(Transport, MonitorSeesFramesAndErrorFramesButCannotSend) {
  transport::BrokerServer server(io_, broker_);
  const std::string ep = Listen(server);
  BrokerClientOptions options;
  options.endpoint = ep;
  options.node_name = "capture";
  options.monitor = true;
  BrokerClientPort monitor(io_, options);
  std::vector<std::string> seen;
  monitor.OnReceive(
      [&](const CanFrame& f, BusTime) { seen.push_back(ToCandump(f) + (f.error() ? "!" : "")); });
  auto a = Client(ep, "a");
  ASSERT_TRUE(RunUntil([&] { return a->Connected() && monitor.Connected(); }));
  EXPECT_FALSE(monitor.Send(CanFrame::Data(0x100, {1})));
  // A alone (the monitor does not acknowledge): ACK errors, seen as error frames.
  a->Send(CanFrame::Data(0x181, {0xAA}));
  ASSERT_TRUE(RunUntil([&] { return !seen.empty(); }));
  EXPECT_EQ(seen[0], "181#!");
  auto b = Client(ep, "b");  // an acknowledger: the frame finally goes through
  ASSERT_TRUE(RunUntil([&] { return std::find(seen.begin(), seen.end(), "181#AA") != seen.end(); }));
}

// Acceptance filters in real time (orchestrator/broker/README.md "Acceptance filters"): a node
// is sent only the identifiers it listens to, and a filter changed by a command the node answers
// reaches the broker ahead of the answer, so a peer reacting to the answer is heard.
TEST_F(Transport, ARealTimeNodeGetsOnlyWhatItsFilterTakesAndANewFilterTravelsAheadOfTheAnswer) {
  transport::BrokerServer server(io_, broker_);
  auto [master, node] = ConnectedPair(server);
  ASSERT_TRUE(master->Connected() && node->Connected());
  std::vector<std::uint32_t> listened{0x000, 0x605};
  node->OnAcceptance([&] { return std::optional(listened); });
  std::vector<std::string> node_got;
  std::vector<std::string> master_got;
  node->OnReceive([&](const CanFrame& f, BusTime) {
    node_got.push_back(ToCandump(f));
    if (f.id == 0x605) {
      // An "SDO download" that makes the node listen to an RPDO as well, answered at once: the
      // new filter leaves in the same write as the answer, and first.
      listened.push_back(0x205);
      ASSERT_TRUE(node->Send(CanFrame::Data(0x585, {0x60})));
    }
  });
  master->OnReceive([&](const CanFrame& f, BusTime) {
    master_got.push_back(ToCandump(f));
    if (f.id == 0x585) {
      ASSERT_TRUE(master->Send(CanFrame::Data(0x205, {0x42})));  // reacts at once
    }
  });
  // The node's first write carries its filter: once the master hears it, the filter is in place.
  ASSERT_TRUE(node->Send(CanFrame::Data(0x705, {0x7F})));
  ASSERT_TRUE(RunUntil([&] { return master_got.size() == 1; }));
  node_got.clear();
  const auto filtered_before = server.Stats().filtered_frames;
  ASSERT_TRUE(master->Send(CanFrame::Data(0x181, {1})));     // another node's TPDO: not for it
  ASSERT_TRUE(master->Send(CanFrame::Data(0x205, {0x41})));  // its RPDO, not configured yet
  ASSERT_TRUE(master->Send(CanFrame::Data(0x605, {0x23, 0x00, 0x14, 0x01})));
  ASSERT_TRUE(RunUntil([&] { return node_got.size() >= 2; })) << node_got.size();
  EXPECT_EQ(node_got, (std::vector<std::string>{"605#23001401", "205#42"}));
  EXPECT_EQ(server.Stats().filtered_frames - filtered_before, 2u);
  EXPECT_EQ(node->Stats().rx_frames, 2u);  // nothing else woke it
}

/// A PortSink for a port driven from the test itself.
struct NullSink : broker::PortSink {
  void Deliver(std::span<const broker::TimedFrame>) override {}
  void ControllerChanged(const ControllerEvent&) override {}
};

TEST_F(Transport, ASlowReaderLosesFramesAndNobodyElseDoes) {
  // A node that stops reading is not allowed to make the broker buffer without bound: beyond
  // BrokerServerOptions::max_backlog_bytes its deliveries are dropped and counted; the others go on.
  LogCapture log;
  broker_.AddBus({.name = "fast", .bitrate = 1'000'000, .paced = false, .tx_queue_capacity = 1 << 20});
  transport::BrokerServer server(io_, broker_, {.max_backlog_bytes = 64 * 1024});
  const std::string ep = Listen(server);
  RawConnection sleeper(ep);  // says Hello, then never reads
  wire::MessageWriter hello;
  hello.AddHello(wire::MakeHello("fast", "sleeper"));
  ASSERT_TRUE(sleeper.Send(std::vector<std::uint8_t>(hello.Bytes().begin(), hello.Bytes().end())));
  auto reader = Client(ep, "reader", "fast");
  std::size_t read = 0;
  reader->OnReceive([&](const CanFrame&, BusTime) { ++read; });
  ASSERT_TRUE(RunUntil([&] { return reader->Connected() && broker_.Ports("fast").size() == 2; }));
  NullSink sink;
  const broker::PortId sender = broker_.Attach("fast", "sender", sink);
  constexpr std::size_t kFrames = 100'000;  // 2.4 MB of records: far beyond socket buffers + 64 KiB
  std::vector<CanFrame> burst(1000, CanFrame::Data(0x181, {1, 2, 3, 4, 5, 6, 7, 8}));
  for (std::size_t sent = 0; sent < kFrames; sent += burst.size()) {
    broker_.Submit(sender, burst);
    ASSERT_TRUE(RunUntil([&] { return read >= sent + burst.size(); })) << read;
  }
  EXPECT_EQ(read, kFrames);
  EXPECT_GT(server.Stats().backlog_drops, 0u);
  EXPECT_LT(server.Stats().backlog_drops, kFrames);
  EXPECT_NE(log.Text().find("[sleeper on fast, port 1]: not reading; dropping frames for it"),
            std::string::npos)
      << "log (" << log.Text().size() << " bytes):\n"
      << log.Text();
}

TEST_F(Transport, ANodeThatStaysBehindIsDisconnectedWithTheReason) {
  // Issue 32: a client that cannot keep up is not held with a full queue for ever: once its
  // backlog has been full for slow_reader_limit, its session is closed and the reason logged.
  LogCapture log;
  broker_.AddBus({.name = "fast", .bitrate = 1'000'000, .paced = false, .tx_queue_capacity = 1 << 20});
  transport::BrokerServer server(io_, broker_, {.max_backlog_bytes = 64 * 1024, .slow_reader_limit = 300ms});
  const std::string ep = Listen(server);
  RawConnection sleeper(ep);  // says Hello, then never reads
  wire::MessageWriter hello;
  hello.AddHello(wire::MakeHello("fast", "sleeper"));
  ASSERT_TRUE(sleeper.Send(std::vector<std::uint8_t>(hello.Bytes().begin(), hello.Bytes().end())));
  ASSERT_TRUE(RunUntil([&] { return broker_.Ports("fast").size() == 1; }));
  NullSink sink;
  const broker::PortId sender = broker_.Attach("fast", "sender", sink);
  std::vector<CanFrame> burst(1000, CanFrame::Data(0x181, {1, 2, 3, 4, 5, 6, 7, 8}));
  ASSERT_TRUE(RunUntil([&] {
    broker_.Submit(sender, burst);
    return server.Stats().slow_readers == 1;
  })) << "the sleeper is still connected";
  EXPECT_EQ(broker_.Ports("fast").size(), 1u) << "only the sender is left";
  EXPECT_NE(log.Text().find("[sleeper on fast, port 1]: closed: not reading:"), std::string::npos)
      << log.Text();
  EXPECT_NE(log.Text().find("frames dropped over 300 ms"), std::string::npos) << log.Text();
}

TEST_F(Transport, ASlowReaderGetsEveryFrameInOrderWhenItsSocketFills) {
  // When a delivery goes to the socket only in part (its buffer is full), the rest is kept and
  // written later, and later deliveries queue behind it: the byte stream stays whole. The reader
  // reads slowly from its own thread; 2.4 MB of records overflow the socket buffer many times.
  broker_.AddBus({.name = "fast", .bitrate = 1'000'000, .paced = false, .tx_queue_capacity = 1 << 20});
  transport::BrokerServer server(io_, broker_);
  const std::string ep = Listen(server);
  constexpr std::size_t kFrames = 100'000;
  std::vector<std::uint32_t> seen;  // the counter in each frame, in arrival order (reader thread)
  std::atomic<bool> attached = false;
  std::atomic<bool> done = false;
  std::thread reader([&] {
    RawConnection raw(ep);
    wire::MessageWriter hello;
    hello.AddHello(wire::MakeHello("fast", "slow"));
    raw.Send(std::vector<std::uint8_t>(hello.Bytes().begin(), hello.Bytes().end()));
    wire::StreamDecoder decoder;
    wire::Message m;
    while (seen.size() < kFrames) {
      const auto got = raw.ReadAtLeast(1);
      if (got.bytes.empty()) break;
      decoder.Feed(got.bytes);
      for (;;) {
        const auto result = decoder.Next(m);
        if (result != wire::StreamDecoder::Result::kMessage) break;
        if (m.type == wire::MessageType::kHelloReply) attached = true;
        for (std::size_t i = 0; i < m.frames.size(); ++i) {
          const CanFrame f = m.frames[i].frame;
          seen.push_back(f.data[0] | f.data[1] << 8 | f.data[2] << 16);
        }
      }
      std::this_thread::sleep_for(10ms);  // 64 KiB per 10 ms: far slower than the broker delivers
    }
    done = true;
  });
  ASSERT_TRUE(RunUntil([&] { return attached.load(); }));
  NullSink sink;
  const broker::PortId sender = broker_.Attach("fast", "sender", sink);
  std::vector<CanFrame> burst;
  for (std::uint32_t next = 0; next < kFrames;) {
    burst.clear();
    for (std::size_t i = 0; i < 1000; ++i, ++next)
      burst.push_back(
          CanFrame::Data(0x181, {std::uint8_t(next), std::uint8_t(next >> 8), std::uint8_t(next >> 16)}));
    broker_.Submit(sender, burst);
    io_.restart();
    io_.poll();  // the round runs and is written (in part, once the socket is full)
  }
  ASSERT_TRUE(RunUntil([&] { return done.load(); }));
  reader.join();
  ASSERT_EQ(seen.size(), kFrames);
  for (std::uint32_t i = 0; i < kFrames; ++i)
    ASSERT_EQ(seen[i], i) << "frame " << i;
  EXPECT_GT(server.Stats().partial_writes, 0u);
  EXPECT_EQ(server.Stats().backlog_drops, 0u);
}

TEST_F(Transport, BrokerAnswersPing) {
  transport::BrokerServer server(io_, broker_);
  const std::string ep = Listen(server);
  std::vector<wire::Message> replies;  // written by the peer thread until `done`
  std::atomic<bool> done = false;
  std::thread peer([&] {
    RawConnection raw(ep);
    wire::MessageWriter w;
    w.AddPing(7);  // allowed before Hello, like a liveness probe
    w.AddHello(wire::MakeHello("can0", "pinger"));
    w.AddPing(8);
    raw.Send(std::vector<std::uint8_t>(w.Bytes().begin(), w.Bytes().end()));
    wire::StreamDecoder decoder;
    wire::Message m;
    while (replies.size() < 3) {
      const auto got = raw.ReadAtLeast(1);
      if (got.bytes.empty()) break;
      decoder.Feed(got.bytes);
      while (decoder.Next(m) == wire::StreamDecoder::Result::kMessage)
        replies.push_back(m);
    }
    done = true;
  });
  ASSERT_TRUE(RunUntil([&] { return done.load(); }));
  peer.join();
  ASSERT_EQ(replies.size(), 3u);
  EXPECT_EQ(replies[0].type, wire::MessageType::kPong);
  EXPECT_EQ(replies[0].envelope.pong().nonce(), 7u);
  EXPECT_EQ(replies[1].type, wire::MessageType::kHelloReply);
  EXPECT_TRUE(replies[1].envelope.hello_reply().accepted());
  EXPECT_EQ(replies[2].envelope.pong().nonce(), 8u);
}

// A client that stamps received frames as captures and socketcand do (the Python participant) learns
// the wall-clock time of bus time 0 from its HelloReply (canfleet_wire.proto, HelloReply.wall_origin_ns).
TEST_F(Transport, HelloReplyCarriesTheWallClockOriginOfBusTime) {
  transport::BrokerServerOptions options;
  options.wall_origin = WallTime(std::chrono::nanoseconds(1'700'000'000'123'456'789));
  transport::BrokerServer server(io_, broker_, options);
  const std::string ep = Listen(server);
  std::optional<wire::Message> reply;  // written by the peer thread until `done`
  std::atomic<bool> done = false;
  std::thread peer([&] {
    RawConnection raw(ep);
    wire::MessageWriter w;
    w.AddHello(wire::MakeHello("can0", "stamper"));
    raw.Send(std::vector<std::uint8_t>(w.Bytes().begin(), w.Bytes().end()));
    wire::StreamDecoder decoder;
    wire::Message m;
    while (!reply) {
      const auto got = raw.ReadAtLeast(1);
      if (got.bytes.empty()) break;
      decoder.Feed(got.bytes);
      if (decoder.Next(m) == wire::StreamDecoder::Result::kMessage) reply = m;
    }
    done = true;
  });
  ASSERT_TRUE(RunUntil([&] { return done.load(); }));
  peer.join();
  ASSERT_TRUE(reply);
  ASSERT_EQ(reply->type, wire::MessageType::kHelloReply);
  EXPECT_TRUE(reply->envelope.hello_reply().accepted());
  EXPECT_EQ(reply->envelope.hello_reply().wall_origin_ns(), 1'700'000'000'123'456'789);
}

// ---- NodeRequest / NodeReply (remote I/O) -------------------------------------------------------

wire::NodeRequest IoGetRequest(std::uint64_t id, const std::string& name) {
  wire::NodeRequest r;
  r.set_request_id(id);
  r.mutable_io_get()->set_name(name);
  return r;
}

TEST_F(Transport, ANodeRequestReachesTheNamedNodeAndItsReplyComesBack) {
  transport::BrokerServer server(io_, broker_);
  const std::string ep = Listen(server);
  broker_.AddBus({.name = "can1", .bitrate = 500'000});
  auto quad = Client(ep, "quad-5");
  auto other = Client(ep, "quad-5", "can1");  // same name, other bus: not asked
  auto plain = Client(ep, "plain");           // serves no requests
  std::vector<std::string> seen;
  quad->OnNodeRequest([&](const wire::NodeRequest& r) {
    seen.push_back(test::WireText(r));
    wire::NodeReply reply;
    auto* v = reply.add_values();
    v->set_name(r.io_get().name());
    v->set_value("2500");
    v->set_unit("mV");
    v->set_input(true);
    return reply;
  });
  other->OnNodeRequest([&](const wire::NodeRequest&) {
    ADD_FAILURE() << "the node on can1 was asked";
    return wire::NodeReply();
  });
  ASSERT_TRUE(RunUntil([&] { return quad->Connected() && other->Connected() && plain->Connected(); }));

  std::vector<std::optional<wire::NodeReply>> replies;
  auto collect = [&](std::optional<wire::NodeReply> r) { replies.push_back(std::move(r)); };
  server.RequestNode("can0", "quad-5", IoGetRequest(77, "IN1.voltage_mV"), collect);
  server.RequestNode("can0", "quad-5", IoGetRequest(77, "IN2.voltage_mV"),
                     collect);  // ids need not be unique
  server.RequestNode("can0", "plain", IoGetRequest(5, ""), collect);
  server.RequestNode("can0", "nobody", IoGetRequest(6, ""), collect);
  server.RequestNode("can2", "quad-5", IoGetRequest(7, ""), collect);
  EXPECT_TRUE(replies.empty());  // never from inside RequestNode
  ASSERT_TRUE(RunUntil([&] { return replies.size() == 5; }));
  RunUntil([] { return false; }, 50ms);  // nothing more arrives
  ASSERT_EQ(replies.size(), 5u);

  // Unknown node and unknown bus: nullopt; the others answered (in any order).
  std::vector<std::string> answered;
  for (const auto& r : replies)
    if (r) answered.push_back(test::WireText(*r));
  ASSERT_EQ(answered.size(), 3u);
  std::sort(answered.begin(), answered.end());
  EXPECT_EQ(answered,
            (std::vector<std::string>{
                R"(request_id: 5 error: "plain serves no node requests")",
                R"(request_id: 77 values { name: "IN1.voltage_mV" value: "2500" unit: "mV" input: true })",
                R"(request_id: 77 values { name: "IN2.voltage_mV" value: "2500" unit: "mV" input: true })",
            }));
  ASSERT_EQ(seen.size(), 2u);
  EXPECT_NE(seen[0].find("io_get { name: \"IN1.voltage_mV\" }"), std::string::npos) << seen[0];
  EXPECT_EQ(server.Stats().node_requests, 5u);
  EXPECT_EQ(server.Stats().node_replies, 3u);
}

/// Attaches a raw connection that says Hello as `name` on can0 and then never reads or answers.
std::unique_ptr<RawConnection> SilentNode(const std::string& endpoint, const std::string& name) {
  auto raw = std::make_unique<RawConnection>(endpoint);
  wire::MessageWriter hello;
  hello.AddHello(wire::MakeHello("can0", name));
  EXPECT_TRUE(raw->Send(std::vector<std::uint8_t>(hello.Bytes().begin(), hello.Bytes().end())));
  return raw;
}

TEST_F(Transport, ANodeThatDoesNotAnswerTimesOut) {
  LogCapture log;
  transport::BrokerServer server(io_, broker_, {.node_request_timeout = 200ms});
  const std::string ep = Listen(server);
  auto silent = SilentNode(ep, "mute");
  ASSERT_TRUE(RunUntil([&] { return broker_.Ports("can0").size() == 1; }));
  int calls = 0;
  std::optional<wire::NodeReply> reply = wire::NodeReply();
  const auto start = std::chrono::steady_clock::now();
  server.RequestNode("can0", "mute", IoGetRequest(1, ""), [&](std::optional<wire::NodeReply> r) {
    ++calls;
    reply = std::move(r);
  });
  ASSERT_TRUE(RunUntil([&] { return calls == 1; }));
  EXPECT_GE(std::chrono::steady_clock::now() - start, 200ms);
  EXPECT_FALSE(reply);
  RunUntil([] { return false; }, 50ms);
  EXPECT_EQ(calls, 1);
  EXPECT_NE(log.Text().find("no reply to node request 1 within 200 ms"), std::string::npos) << log.Text();
}

TEST_F(Transport, ADisconnectEndsPendingRequestsAtOnce) {
  transport::BrokerServer server(io_, broker_, {.node_request_timeout = 60s});
  const std::string ep = Listen(server);
  auto silent = SilentNode(ep, "mute");
  ASSERT_TRUE(RunUntil([&] { return broker_.Ports("can0").size() == 1; }));
  int calls = 0;
  bool got_reply = true;
  for (int i = 0; i < 3; ++i)
    server.RequestNode("can0", "mute", IoGetRequest(1, ""), [&](std::optional<wire::NodeReply> r) {
      ++calls;
      got_reply = got_reply && r.has_value();
    });
  RunUntil([] { return false; }, 20ms);
  EXPECT_EQ(calls, 0);
  silent.reset();
  ASSERT_TRUE(RunUntil([&] { return calls == 3; }, 5s));  // far below the 60 s timeout
  EXPECT_FALSE(got_reply);
}

TEST_F(Transport, ClosingTheServerEndsPendingRequests) {
  auto server = std::make_unique<transport::BrokerServer>(io_, broker_);
  const std::string ep = Listen(*server);
  auto silent = SilentNode(ep, "mute");
  ASSERT_TRUE(RunUntil([&] { return broker_.Ports("can0").size() == 1; }));
  int calls = 0;
  server->RequestNode("can0", "mute", IoGetRequest(1, ""), [&](std::optional<wire::NodeReply> r) {
    ++calls;
    EXPECT_FALSE(r);
  });
  RunUntil([] { return false; }, 20ms);
  server.reset();
  RunUntil([&] { return calls == 1; });
  EXPECT_EQ(calls, 1);
}

TEST_F(Transport, ANodeReplyBeforeHelloOrANodeRequestFromANodeIsAProtocolError) {
  transport::BrokerServer server(io_, broker_);
  const std::string ep = Listen(server);
  std::atomic<int> closed = 0;
  std::thread peer([&] {
    {
      RawConnection raw(ep);
      wire::MessageWriter w;
      w.AddNodeReply(wire::NodeReply());
      raw.Send(std::vector<std::uint8_t>(w.Bytes().begin(), w.Bytes().end()));
      if (raw.ReadUntilClosed().closed) ++closed;
    }
    {
      RawConnection raw(ep);
      wire::MessageWriter w;
      w.AddHello(wire::MakeHello("can0", "confused"));
      w.AddNodeRequest(IoGetRequest(1, ""));
      raw.Send(std::vector<std::uint8_t>(w.Bytes().begin(), w.Bytes().end()));
      if (raw.ReadUntilClosed().closed) ++closed;
    }
  });
  ASSERT_TRUE(RunUntil([&] { return closed.load() == 2; }));
  peer.join();
  EXPECT_EQ(server.Stats().protocol_errors, 2u);
}

// Protocol v3: a node states its controller's bit rate in its Hello and each switch in a
// BitRate message; the broker runs its port at that rate (orchestrator/broker/README.md "Bit
// rate"): at another rate than the bus, the node sees error frames and no traffic, and logs them.
TEST_F(Transport, ANodeAtAnotherBitRateSeesErrorFramesUntilItSwitchesBack) {
  transport::BrokerServer server(io_, broker_);
  const std::string ep = Listen(server);
  BrokerClientOptions options;
  options.endpoint = ep;
  options.node_name = "b";
  options.bitrate = 250'000;  // the bus runs at 1 Mbit/s
  BrokerClientPort b(io_, options);
  std::vector<std::string> seen;
  b.OnReceive([&](const CanFrame& f, BusTime) { seen.push_back(ToCandump(f) + (f.error() ? "!" : "")); });
  auto a = Client(ep, "a");
  auto c = Client(ep, "c");
  ASSERT_TRUE(RunUntil([&] { return a->Connected() && b.Connected() && c->Connected(); }));
  const auto port = broker_.NewestPortNamed("can0", "b");
  ASSERT_TRUE(port.has_value());
  EXPECT_EQ(broker_.Port(*port).bitrate, 250'000u);

  ASSERT_TRUE(a->Send(CanFrame::Data(0x181, {0xAA})));
  ASSERT_TRUE(RunUntil([&] { return !seen.empty(); }));
  EXPECT_EQ(seen, (std::vector<std::string>{"181#!"}));
  EXPECT_EQ(b.Stats().rx_error_frames, 1u);

  ASSERT_TRUE(b.SetBitRate(0));  // back to the bus's rate
  EXPECT_EQ(b.BitRate(), 0u);
  ASSERT_TRUE(RunUntil([&] { return broker_.Port(*port).bitrate == 1'000'000u; }));
  ASSERT_TRUE(a->Send(CanFrame::Data(0x181, {0xBB})));
  ASSERT_TRUE(RunUntil([&] { return seen.size() == 2; }));
  EXPECT_EQ(seen[1], "181#BB");
  EXPECT_FALSE(b.SetBitRate(5'000));  // outside 10 kbit/s .. 1 Mbit/s: not the port's to take
}

// A Hello with a rate the broker cannot run is refused; a BitRate message with one is a protocol
// error (canfleet_wire.proto).
TEST_F(Transport, ABitRateOutsideTheRangeIsRefused) {
  transport::BrokerServer server(io_, broker_);
  const std::string ep = Listen(server);
  std::atomic<int> closed = 0;
  std::thread peer([&] {
    {
      RawConnection raw(ep);
      wire::MessageWriter w;
      wire::Hello hello = wire::MakeHello("can0", "too-fast");
      hello.set_bitrate(2'000'000);
      w.AddHello(hello);
      raw.Send(std::vector<std::uint8_t>(w.Bytes().begin(), w.Bytes().end()));
      if (raw.ReadUntilClosed().closed) ++closed;
    }
    {
      RawConnection raw(ep);
      wire::MessageWriter w;
      w.AddHello(wire::MakeHello("can0", "then-too-slow"));
      w.AddBitRate(1'000);
      raw.Send(std::vector<std::uint8_t>(w.Bytes().begin(), w.Bytes().end()));
      if (raw.ReadUntilClosed().closed) ++closed;
    }
  });
  ASSERT_TRUE(RunUntil([&] { return closed.load() == 2; }));
  peer.join();
  EXPECT_EQ(server.Stats().refused, 1u);
  EXPECT_EQ(server.Stats().protocol_errors, 1u);
}

}  // namespace
}  // namespace canfleet::system_test
