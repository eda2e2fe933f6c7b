// The socketcand endpoint on real TCP sockets, with the broker on an Asio event loop (real time):
// what the simulated-time unit tests (tests/unit/socketcand) cannot show, i.e. TCP segments and
// flow control, FIN detection, binding ports, and the raw-mode settle and drain timeout on a real
// clock. Bounds are generous: a loaded machine slows these tests down without failing them.
#include "orchestrator/socketcand/server.hpp"

#include <gtest/gtest.h>

#include <regex>
#include <stdexcept>

#include "tests/integration/socketcand/tcp_endpoint.hpp"
#include "tests/support/bus_probe.hpp"

namespace canfleet::socketcand {
namespace {

using canfleet::test::Frame;
using namespace std::chrono_literals;
using test::Client;
using test::Endpoint;

ServerOptions Compact() {
  ServerOptions o;
  o.align_frames = false;
  o.raw_settle = Duration::zero();
  return o;
}

TEST(SocketcandTcp, HandshakeAsPythonCanExpectsIt) {
  Endpoint ep(Compact());
  Client c(ep.port());
  ASSERT_TRUE(c.connected());
  EXPECT_EQ(c.RecvOnce(256), "< hi >");
  c.Send("< open can0 >");
  EXPECT_EQ(c.RecvOnce(256), "< ok >");
  c.Send("< rawmode >");
  EXPECT_EQ(c.RecvOnce(256), "< ok >");
  EXPECT_EQ(ep.PortsOnBus(), 2u) << "the session is a port of the bus";
}

TEST(SocketcandTcp, RawModeForwardsEveryFrameOfTheOtherPorts) {
  Endpoint ep(Compact());
  Client c(ep.port());
  ASSERT_TRUE(c.Handshake());
  CanFrame small_ext = Frame("123#01");
  small_ext.flags |= CanFrame::kExtended;
  ep.Send({Frame("123#DEADBEEF"), Frame("1ABCDEF0#0011223344556677"), small_ext, Frame("080#"),
           CanFrame::Remote(0x705, 1)});
  const std::regex frame(R"(< frame ([0-9A-F]+) (\d{10})\.(\d{6}) ([0-9A-F]*) >)");
  // One port's frames go on the wire in the order it queued them (a CAN driver's FIFO).
  const std::vector<std::pair<std::string, std::string>> expected = {
      {"123", "DEADBEEF"}, {"1ABCDEF0", "0011223344556677"}, {"00000123", "01"}, {"080", ""}};
  const auto now = std::chrono::system_clock::now().time_since_epoch();
  for (const auto& [id, data] : expected) {
    const auto m = c.Next();
    ASSERT_TRUE(m.has_value());
    std::smatch match;
    ASSERT_TRUE(std::regex_match(*m, match, frame)) << *m;
    EXPECT_EQ(match[1], id);
    EXPECT_EQ(match[4], data);
    const auto seconds = std::stoll(match[2]);
    EXPECT_NEAR(static_cast<double>(seconds), std::chrono::duration<double>(now).count(), 5.0)
        << "timestamps are wall-clock time";
  }
  const auto rtr = c.Next();
  ASSERT_TRUE(rtr.has_value());
  EXPECT_TRUE(std::regex_match(*rtr, std::regex(R"(< rtr 705 \d+\.\d{6} 1 >)"))) << *rtr;
}

TEST(SocketcandTcp, ClientFramesReachTheBusAndAreNotEchoed) {
  Endpoint ep(Compact());
  Client c(ep.port());
  ASSERT_TRUE(c.Handshake());
  c.Send("< send 181 3 de ad 5 >< send 1AAAAAAA 2 1 F1 >< sendrtr 705 0 >");
  c.Send("< send 00000181 0 >");
  const auto got = ep.WaitReceived(4);
  EXPECT_EQ(got, (std::vector<CanFrame>{Frame("181#DEAD05"), Frame("1AAAAAAA#01F1"),
                                        CanFrame::Remote(0x705, 0), Frame("00000181#")}))
      << "in the order the client sent them";
  ep.Send({Frame("7FF#AA")});
  const auto first = c.Next();
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(first->substr(0, 12), "< frame 7FF ") << "the client's own frames are not echoed back";
  EXPECT_EQ(ep.Stats().frames_from_clients, 4u);
}

TEST(SocketcandTcp, ADisconnectedClientsPortIsDetached) {
  Endpoint ep(Compact());
  {
    Client c(ep.port());
    ASSERT_TRUE(c.Handshake());
    EXPECT_EQ(ep.PortsOnBus(), 2u);
  }
  for (int i = 0; i < 1000 && ep.PortsOnBus() != 1; ++i)
    std::this_thread::sleep_for(10ms);
  EXPECT_EQ(ep.PortsOnBus(), 1u);
}

TEST(SocketcandTcp, AlignedFramesAreWholeSixtyFourByteRecords) {
  ServerOptions o;
  o.raw_settle = Duration::zero();
  Endpoint ep(o);
  Client c(ep.port());
  ASSERT_TRUE(c.Handshake());
  std::vector<CanFrame> frames;
  for (std::uint32_t i = 0; i < 200; ++i)
    frames.push_back(CanFrame::Data(0x100 + i, {static_cast<std::uint8_t>(i), 1, 2}));
  ep.Send(frames);
  std::string all;
  while (all.size() < 200 * kAlignedRecordSize) {
    const auto chunk = c.RecvOnce(1024);
    ASSERT_TRUE(chunk.has_value() && !chunk->empty());
    EXPECT_EQ(chunk->size() % kAlignedRecordSize, 0u) << "every read ends at a record boundary";
    EXPECT_EQ(chunk->back(), '>');
    all += *chunk;
  }
  EXPECT_EQ(all.size(), 200 * kAlignedRecordSize);
}

// python-can reads the "< ok >" of rawmode with one recv() and compares it exactly: frames are
// held for raw_settle after it has been written.
TEST(SocketcandTcp, FramesWaitUntilTheRawModeReplyHasSettled) {
  ServerOptions o = Compact();
  o.raw_settle = 150ms;
  Endpoint ep(o);
  Client c(ep.port());
  EXPECT_EQ(c.RecvOnce(256), "< hi >");
  c.Send("< open can0 >");
  EXPECT_EQ(c.RecvOnce(256), "< ok >");
  c.Send("< rawmode >");
  EXPECT_EQ(c.RecvOnce(256), "< ok >");
  const auto ok_at = std::chrono::steady_clock::now();
  ep.Send({Frame("123#01")});  // a frame right after the reply
  const auto frame = c.Next(1s);
  const auto waited = std::chrono::steady_clock::now() - ok_at;
  ASSERT_TRUE(frame.has_value());
  EXPECT_EQ(frame->substr(0, 12), "< frame 123 ");
  EXPECT_GE(waited, 100ms) << "held until the reply has settled";
}

// A client sending faster than the bus carries is not read while its port's queue is full, so
// nothing is dropped even with a TX queue smaller than the burst.
TEST(SocketcandTcp, FastClientIsThrottledNotDropped) {
  ServerOptions o = Compact();
  o.max_tx_backlog = 64;
  Endpoint ep(o, {.name = "can0", .bitrate = 1'000'000, .tx_queue_capacity = 100});
  Client c(ep.port());
  ASSERT_TRUE(c.Handshake());
  std::string burst;
  std::vector<CanFrame> expected;
  for (int i = 0; i < 1000; ++i) {
    const CanFrame f =
        CanFrame::Data(0x200, {static_cast<std::uint8_t>(i), static_cast<std::uint8_t>(i >> 8)});
    burst += FormatSend(f);
    expected.push_back(f);
  }
  c.Send(burst);
  EXPECT_EQ(ep.WaitReceived(1000, 10s), expected);
  EXPECT_EQ(ep.Stats().submit_drops, 0u);
}

// A client that does not read cannot make the server buffer without bound: beyond
// max_output_bytes frames are dropped and counted; what was kept arrives in order.
TEST(SocketcandTcp, SlowClientsOutputIsBounded) {
  ServerOptions o = Compact();
  o.max_output_bytes = 4096;
  Endpoint ep(o, {.name = "can0", .bitrate = 1'000'000, .paced = false, .tx_queue_capacity = 100'000});
  Client c(ep.port(), 1024);
  ASSERT_TRUE(c.Handshake());
  std::vector<CanFrame> frames;
  for (std::uint32_t i = 0; i < 20000; ++i)
    frames.push_back(
        CanFrame::Data(0x100, {static_cast<std::uint8_t>(i), static_cast<std::uint8_t>(i >> 8)}));
  ep.Send(frames);
  auto stats = ep.Stats();
  for (int i = 0; i < 3000 && stats.output_drops + stats.frames_to_clients < 20000; ++i) {
    std::this_thread::sleep_for(10ms);
    stats = ep.Stats();
  }
  EXPECT_GT(stats.output_drops, 0u);
  EXPECT_EQ(stats.output_drops + stats.frames_to_clients, 20000u);
  std::uint64_t received = 0;
  int last = -1;
  while (received < stats.frames_to_clients) {
    const auto m = c.Next();
    ASSERT_TRUE(m.has_value()) << "after " << received << " frames";
    const int value = std::stoi(m->substr(m->size() - 6, 2), nullptr, 16) |
                      (std::stoi(m->substr(m->size() - 4, 2), nullptr, 16) << 8);
    EXPECT_GT(value, last);
    last = value;
    ++received;
  }
}

// Issue 32: a client that stays behind is not kept with a full queue for ever: once frames have
// been dropped for it for slow_client_limit, it is disconnected.
TEST(SocketcandTcp, AClientThatStaysBehindIsDisconnected) {
  ServerOptions o = Compact();
  o.max_output_bytes = 4096;
  o.slow_client_limit = 200ms;
  Endpoint ep(o, {.name = "can0", .bitrate = 1'000'000, .paced = false, .tx_queue_capacity = 100'000});
  Client c(ep.port(), 1024);
  ASSERT_TRUE(c.Handshake());
  std::vector<CanFrame> frames(2000, CanFrame::Data(0x100, {1, 2}));
  auto stats = ep.Stats();
  for (int i = 0; i < 3000 && stats.slow_clients == 0; ++i) {
    ep.Send(frames);
    std::this_thread::sleep_for(10ms);
    stats = ep.Stats();
  }
  EXPECT_EQ(stats.slow_clients, 1u);
  EXPECT_GT(stats.output_drops, 0u);
}

// Issue 32: sessions are bounded (each may queue max_output_bytes): one more is told and closed.
TEST(SocketcandTcp, SessionsBeyondTheLimitAreRefused) {
  ServerOptions o = Compact();
  o.max_sessions = 2;
  Endpoint ep(o, {.name = "can0", .bitrate = 1'000'000, .paced = false});
  Client a(ep.port()), b(ep.port());
  ASSERT_TRUE(a.Handshake());
  ASSERT_TRUE(b.Handshake());
  Client c(ep.port());
  const auto refusal = c.Next();
  ASSERT_TRUE(refusal.has_value());
  EXPECT_EQ(*refusal, "< error too many connections >");
  EXPECT_EQ(ep.Stats().sessions_refused, 1u);
}

// A CAN driver sends what was queued before its socket closed: a script that sends a burst and
// exits at once loses nothing.
TEST(SocketcandTcp, FramesSentJustBeforeClosingStillReachTheBus) {
  ServerOptions o = Compact();
  o.max_tx_backlog = 32;
  Endpoint ep(o, {.name = "can0", .bitrate = 125'000});  // ~1 ms per frame: the burst outlives the client
  std::string burst;
  std::vector<CanFrame> expected;
  for (int i = 0; i < 300; ++i) {
    const CanFrame f =
        CanFrame::Data(0x300, {static_cast<std::uint8_t>(i), static_cast<std::uint8_t>(i >> 8)});
    burst += FormatSend(f);
    expected.push_back(f);
  }
  {
    Client c(ep.port());
    ASSERT_TRUE(c.Handshake());
    c.Send(burst);
  }
  EXPECT_EQ(ep.WaitReceived(300, 10s), expected);
  for (int i = 0; i < 1000 && ep.PortsOnBus() != 1; ++i)
    std::this_thread::sleep_for(10ms);
  EXPECT_EQ(ep.PortsOnBus(), 1u) << "the session leaves once its frames are on the wire";
}

// A port alone on a bus never gets an ACK (its frames stay queued): after drain_timeout the
// session of a client that left is closed anyway.
TEST(SocketcandTcp, ALeftClientsSessionEndsAfterTheDrainTimeout) {
  ServerOptions o = Compact();
  o.drain_timeout = 2s;
  Endpoint ep(o);
  ep.DetachCpp();
  {
    Client c(ep.port());
    ASSERT_TRUE(c.Handshake());
    c.Send("< send 123 1 01 >");
    ep.WaitReceived(1, 100ms);  // the frame reaches the broker's queue (nobody acknowledges it)
  }
  const auto left = std::chrono::steady_clock::now();
  for (int i = 0; i < 1000 && ep.PortsOnBus() != 0; ++i)
    std::this_thread::sleep_for(10ms);
  EXPECT_EQ(ep.PortsOnBus(), 0u);
  EXPECT_GE(std::chrono::steady_clock::now() - left, 1900ms) << "not before the drain timeout";
}

TEST(SocketcandTcp, ServeChecksTheBusAndDefaultsToPort29536) {
  asio::io_context io;
  AsioScheduler scheduler(io);
  broker::Broker broker(scheduler);
  broker.AddBus({.name = "can0"});
  Server server(io, broker, scheduler);
  EXPECT_THROW(server.Serve("can9", 0), std::invalid_argument);
  std::uint16_t port = 0;
  try {
    port = server.Serve("can0");
  } catch (const std::system_error& e) {
    GTEST_SKIP() << "port 29536 is in use here: " << e.what();
  }
  EXPECT_EQ(port, kDefaultPort);
  EXPECT_THROW(server.Serve("can0", 0), std::invalid_argument);
}

TEST(SocketcandTcp, StopClosesSessions) {
  Endpoint ep(Compact());
  Client c(ep.port());
  ASSERT_TRUE(c.Handshake());
  ep.OnIo([&] { ep.server().Stop(); });
  EXPECT_TRUE(c.ClosedByServer());
  EXPECT_EQ(ep.PortsOnBus(), 1u);
}

}  // namespace
}  // namespace canfleet::socketcand
