// The socketcand endpoint's sessions on simulated time (sim_endpoint.hpp: socketpair clients, the
// broker on a SimulatedScheduler). Replies and formats as linux-can/socketcand sends them
// (state_nobus.c, state_raw.c). The same endpoint over real TCP and real time:
// tests/integration/socketcand.
#include "orchestrator/socketcand/server.hpp"

#include <gtest/gtest.h>

#include <regex>
#include <stdexcept>

#include "tests/support/bus_probe.hpp"
#include "tests/unit/socketcand/sim_endpoint.hpp"

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

TEST(SocketcandServer, HandshakeAsPythonCanExpectsIt) {
  Endpoint ep(Compact());
  Client c(ep);
  ASSERT_TRUE(c.connected());
  EXPECT_EQ(c.RecvOnce(256), "< hi >");
  c.Send("< open can0 >");
  EXPECT_EQ(c.RecvOnce(256), "< ok >");
  c.Send("< rawmode >");
  EXPECT_EQ(c.RecvOnce(256), "< ok >");
  EXPECT_EQ(ep.PortsOnBus(), 2u) << "the session is a port of the bus";
}

TEST(SocketcandServer, UnknownBusIsRefusedAndTheConnectionClosed) {
  Endpoint ep(Compact());
  Client c(ep);
  EXPECT_EQ(c.RecvOnce(256), "< hi >");
  c.Send("< open can7 >");
  EXPECT_EQ(c.Next(), "< error could not open bus >");
  EXPECT_TRUE(c.ClosedByServer());
  EXPECT_EQ(ep.PortsOnBus(), 1u);
}

TEST(SocketcandServer, MalformedOpenIsRefusedLikeAnUnknownBus) {
  Endpoint ep(Compact());
  Client c(ep);
  EXPECT_EQ(c.RecvOnce(256), "< hi >");
  c.Send("< open >");
  EXPECT_EQ(c.Next(), "< error could not open bus >");
  EXPECT_TRUE(c.ClosedByServer());
}

TEST(SocketcandServer, CommandsBeforeOpenAreUnknownButTheSessionLives) {
  Endpoint ep(Compact());
  Client c(ep);
  EXPECT_EQ(c.RecvOnce(256), "< hi >");
  c.Send("< send 123 0 >");
  EXPECT_EQ(c.Next(), "< error unknown command >");
  c.Send("< rawmode >");
  EXPECT_EQ(c.Next(), "< error unknown command >");
  c.Send("< open can0 >");
  EXPECT_EQ(c.Next(), "< ok >");
  ep.RunFor(50ms);
  EXPECT_TRUE(ep.Received().empty()) << "nothing was sent before open";
}

TEST(SocketcandServer, RawModeForwardsEveryFrameOfTheOtherPorts) {
  Endpoint ep(Compact());
  Client c(ep);
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
        << "timestamps are wall-clock time (bus time 0 = when the server was made)";
  }
  const auto rtr = c.Next();
  ASSERT_TRUE(rtr.has_value());
  EXPECT_TRUE(std::regex_match(*rtr, std::regex(R"(< rtr 705 \d+\.\d{6} 1 >)"))) << *rtr;
}

TEST(SocketcandServer, TimestampsFollowBusTimeFromTheWallClockOrigin) {
  ServerOptions o = Compact();
  o.wall_origin = WallTime{std::chrono::seconds(1'700'000'000)};
  Endpoint ep(o);
  Client c(ep);
  ASSERT_TRUE(c.Handshake());
  ep.RunFor(2500ms);
  ep.Send({Frame("123#01")});
  const auto m = c.Next();
  ASSERT_TRUE(m.has_value());
  // Sent at bus time 2.5 s; on the wire 1 Mbit/s: 1700000002.5xxxxx.
  EXPECT_TRUE(std::regex_match(*m, std::regex(R"(< frame 123 1700000002\.5\d{5} 01 >)"))) << *m;
}

TEST(SocketcandServer, ClientFramesReachTheBusAndAreNotEchoed) {
  Endpoint ep(Compact());
  Client c(ep);
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

TEST(SocketcandServer, SendWorksInBcmModeButFramesAreForwardedInRawModeOnly) {
  Endpoint ep(Compact());
  Client c(ep);
  EXPECT_EQ(c.RecvOnce(256), "< hi >");
  c.Send("< open can0 >");
  EXPECT_EQ(c.Next(), "< ok >");
  c.Send("< send 100 1 01 >");
  EXPECT_EQ(ep.WaitReceived(1), (std::vector<CanFrame>{Frame("100#01")}));
  ep.Send({Frame("200#02")});
  ep.RunFor(10ms);  // 200h is on the wire while the session is in BCM mode
  c.Send("< subscribe 0 0 200 >");
  EXPECT_EQ(c.Next(), "< error command not supported >") << "no frame before it";
  c.Send("< rawmode >");
  EXPECT_EQ(c.Next(), "< ok >");
  ep.Send({Frame("300#03")});
  const auto m = c.Next();
  ASSERT_TRUE(m.has_value());
  EXPECT_EQ(m->substr(0, 12), "< frame 300 ");
  c.Send("< bcmmode >");
  EXPECT_EQ(c.Next(), "< ok >");
  ep.Send({Frame("400#04")});
  ep.RunFor(10ms);  // 400h is on the wire
  c.Send("< echo >");
  EXPECT_EQ(c.Next(), "< echo >") << "no frame forwarded in BCM mode";
}

TEST(SocketcandServer, MalformedSendIsIgnoredAndTheSessionLives) {
  Endpoint ep(Compact());
  Client c(ep);
  ASSERT_TRUE(c.Handshake());
  c.Send("< send 123 2 01 >< send 800000000 0 >< send 123 9 >< send >");
  c.Send("< echo >");
  EXPECT_EQ(c.Next(), "< echo >") << "socketcand does not answer a bad send";
  c.Send("< frobnicate >");
  EXPECT_EQ(c.Next(), "< error unknown command >");
  c.Send("< isotpmode >");
  EXPECT_EQ(c.Next(), "< error mode not supported >");
  c.Send("< send 123 1 01 >");
  EXPECT_EQ(ep.WaitReceived(1), (std::vector<CanFrame>{Frame("123#01")}));
  EXPECT_EQ(ep.Stats().protocol_errors, 6u);
}

TEST(SocketcandServer, GarbageIsSkipped) {
  Endpoint ep(Compact());
  Client c(ep);
  ASSERT_TRUE(c.Handshake());
  std::string garbage;
  for (int i = 0; i < 20000; ++i)
    garbage += static_cast<char>((i * 37) % 256 == '<' ? 0 : (i * 37) % 256);
  c.Send(garbage);
  c.Send("< echo >");
  EXPECT_EQ(c.Next(), "< echo >");
}

TEST(SocketcandServer, OverlongCommandClosesOnlyThatConnection) {
  Endpoint ep(Compact());
  Client bad(ep);
  Client good(ep);
  ASSERT_TRUE(bad.Handshake());
  ASSERT_TRUE(good.Handshake());
  bad.Send("< send " + std::string(1000, '1'));
  EXPECT_TRUE(bad.ClosedByServer());
  good.Send("< send 123 0 >");
  EXPECT_EQ(ep.WaitReceived(1), (std::vector<CanFrame>{Frame("123#")}));
  Client again(ep);
  EXPECT_TRUE(again.Handshake()) << "the server keeps serving";
}

TEST(SocketcandServer, ADisconnectedClientsPortIsDetached) {
  Endpoint ep(Compact());
  Client c(ep);
  ASSERT_TRUE(c.Handshake());
  EXPECT_EQ(ep.PortsOnBus(), 2u);
  c.Close();
  EXPECT_TRUE(ep.RunUntil([&] { return ep.PortsOnBus() == 1; }, 1s));
}

TEST(SocketcandServer, AlignedFramesAreWholeSixtyFourByteRecords) {
  ServerOptions o;
  o.raw_settle = Duration::zero();
  Endpoint ep(o);
  Client c(ep);
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
// held for raw_settle after it has been written, and none is lost.
TEST(SocketcandServer, FramesWaitUntilTheRawModeReplyHasSettled) {
  ServerOptions o = Compact();
  o.raw_settle = 150ms;
  Endpoint ep(o);
  Client c(ep);
  EXPECT_EQ(c.RecvOnce(256), "< hi >");
  c.Send("< open can0 >");
  EXPECT_EQ(c.RecvOnce(256), "< ok >");
  c.Send("< rawmode >");
  EXPECT_EQ(c.RecvOnce(256), "< ok >");
  const TimePoint ok_at = ep.Now();
  ep.Send({Frame("123#01")});  // a frame right after the reply
  EXPECT_EQ(c.Next(149ms), std::nullopt) << "held while the reply settles";
  const auto frame = c.Next(1s);
  ASSERT_TRUE(frame.has_value());
  EXPECT_EQ(frame->substr(0, 12), "< frame 123 ");
  EXPECT_EQ(ep.Now() - ok_at, 150ms) << "released when raw_settle has passed";
}

// A client sending faster than the bus carries is not read while its port's queue is full, so
// nothing is dropped even with a TX queue smaller than the burst.
TEST(SocketcandServer, FastClientIsThrottledNotDropped) {
  ServerOptions o = Compact();
  o.max_tx_backlog = 64;
  Endpoint ep(o, {.name = "can0", .bitrate = 1'000'000, .tx_queue_capacity = 100});
  Client c(ep);
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
TEST(SocketcandServer, SlowClientsOutputIsBounded) {
  ServerOptions o = Compact();
  o.max_output_bytes = 4096;
  Endpoint ep(o, {.name = "can0", .bitrate = 1'000'000, .paced = false, .tx_queue_capacity = 100'000});
  Client c(ep, 4096);  // a small socket buffer between server and client
  ASSERT_TRUE(c.Handshake());
  std::vector<CanFrame> frames;
  for (std::uint32_t i = 0; i < 20000; ++i)
    frames.push_back(
        CanFrame::Data(0x100, {static_cast<std::uint8_t>(i), static_cast<std::uint8_t>(i >> 8)}));
  ep.Send(frames);
  ASSERT_TRUE(ep.RunUntil([&] { return ep.Stats().output_drops + ep.Stats().frames_to_clients == 20000; }));
  const auto stats = ep.Stats();
  EXPECT_GT(stats.output_drops, 0u);
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

// A CAN driver sends what was queued before its socket closed: a script that sends a burst and
// exits at once loses nothing.
TEST(SocketcandServer, FramesSentJustBeforeClosingStillReachTheBus) {
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
    Client c(ep);
    ASSERT_TRUE(c.Handshake());
    c.Send(burst);
  }
  EXPECT_EQ(ep.WaitReceived(300, 10s), expected);
  EXPECT_TRUE(ep.RunUntil([&] { return ep.PortsOnBus() == 1; }, 1s))
      << "the session leaves once its frames are on the wire";
}

// A port alone on a bus never gets an ACK (its frames stay queued): drain_timeout after the client
// left, its session is closed anyway.
TEST(SocketcandServer, ALeftClientsSessionEndsAfterTheDrainTimeout) {
  ServerOptions o = Compact();
  o.drain_timeout = 200ms;
  Endpoint ep(o);
  ep.DetachCpp();
  Client c(ep);
  ASSERT_TRUE(c.Handshake());
  c.Send("< send 123 1 01 >");
  ep.RunFor(20ms);
  c.Close();
  ep.Settle();
  const TimePoint left_at = ep.Now();
  ep.RunFor(199ms);
  EXPECT_EQ(ep.PortsOnBus(), 1u) << "still draining";
  ASSERT_TRUE(ep.RunUntil([&] { return ep.PortsOnBus() == 0; }, 1s));
  EXPECT_EQ(ep.Now() - left_at, 200ms);
}

TEST(SocketcandServer, OfferAndAdoptCheckTheBus) {
  Endpoint ep(Compact());
  EXPECT_THROW(ep.server().Offer("can9"), std::invalid_argument) << "not a bus of the broker";
  EXPECT_THROW(ep.server().Offer("can0"), std::invalid_argument) << "already served";
}

TEST(SocketcandServer, StopClosesSessions) {
  Endpoint ep(Compact());
  Client c(ep);
  ASSERT_TRUE(c.Handshake());
  ep.server().Stop();
  EXPECT_TRUE(c.ClosedByServer());
  EXPECT_EQ(ep.PortsOnBus(), 1u);
}

}  // namespace
}  // namespace canfleet::socketcand
