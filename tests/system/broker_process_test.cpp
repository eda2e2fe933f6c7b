// The node <-> broker transport between real processes (issue 4, "Done when": "Two node-side test
// clients in separate processes exchange frames through the broker over TCP and Unix sockets with
// correct order and timestamps"; "Node <-> broker protocol": reconnection with backoff, logged;
// malformed, oversized or out-of-order messages close that one connection with a logged reason).
//
// Processes: canfleet-broker and canfleet-bus-client (tools/bus_client_main.cpp), which prints
// "rx <bus time ns> <candump frame>" per received frame and "sent N" once the bus has confirmed
// a send command.
#include <gtest/gtest.h>
#include <signal.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <sstream>

#include "bus/wire/message_writer.hpp"
#include "bus/wire/stream_decoder.hpp"
#include "tests/system/support/child_process.hpp"

namespace canfleet::system_test {
namespace {

using namespace std::chrono_literals;

/// A canfleet-broker process, listening where asked; the bound endpoints come from its
/// --ready-file (port 0 becomes the real port).
class BrokerProcess {
 public:
  BrokerProcess(const TempDir& dir, const std::vector<std::string>& listen,
                const std::vector<std::string>& buses) {
    static int instance = 0;
    const std::string tag = std::to_string(++instance);
    const std::string ready = dir.File("ready" + tag);
    log_ = dir.File("broker" + tag + ".log");
    std::vector<std::string> argv = {PROGRAM_CANFLEET_BROKER, "--ready-file", ready, "--log-level", "debug"};
    for (const auto& l : listen) {
      argv.push_back("--listen");
      argv.push_back(l);
    }
    for (const auto& b : buses) {
      argv.push_back("--bus");
      argv.push_back(b);
    }
    process_ = std::make_unique<ChildProcess>(argv, log_);
    if (!WaitUntil([&] { return std::filesystem::exists(ready) || !process_->Running(); }))
      ADD_FAILURE() << "broker not ready:\n" << process_->Log();
    std::ifstream in(ready);
    for (std::string line; std::getline(in, line);)
      endpoints_.push_back(line);
  }

  ChildProcess& process() { return *process_; }
  const std::vector<std::string>& endpoints() const { return endpoints_; }
  std::string Log() const { return process_->Log(); }

 private:
  std::string log_;
  std::unique_ptr<ChildProcess> process_;
  std::vector<std::string> endpoints_;
};

/// A canfleet-bus-client process taking commands on stdin.
std::unique_ptr<ChildProcess> StartClient(const TempDir& dir, const std::string& endpoint,
                                          const std::string& name) {
  return std::make_unique<ChildProcess>(
      std::vector<std::string>{PROGRAM_CANFLEET_BUS_CLIENT, "--connect", endpoint, "--name", name, "--stdin",
                               "--timeout", "240"},
      dir.File(name + ".log"));
}

struct Received {
  std::int64_t time_ns;
  std::string id;
  std::uint32_t seq;
};

/// The "rx" lines of a client, parsed. Sequence numbers are the 4 data bytes "send" puts in.
std::vector<Received> ReceivedFrames(const ChildProcess& client) {
  std::vector<Received> out;
  for (const auto& line : client.Lines()) {
    if (!line.starts_with("rx ")) continue;
    std::istringstream in(line.substr(3));
    std::string time;
    std::string frame;
    in >> time >> frame;
    const auto hash = frame.find('#');
    out.push_back({std::stoll(time), frame.substr(0, hash),
                   static_cast<std::uint32_t>(std::stoul(frame.substr(hash + 1), nullptr, 16))});
  }
  return out;
}

std::size_t CountRx(ChildProcess& client) {
  client.Poll();
  std::size_t n = 0;
  for (const auto& line : client.Lines())
    n += line.starts_with("rx ") ? 1 : 0;
  return n;
}

struct ExchangeCase {
  const char* transport;  // "tcp" or "unix"
  bool paced;
};

class BrokerExchange : public ::testing::TestWithParam<ExchangeCase> {};

TEST_P(BrokerExchange, TwoClientProcessesExchangeFramesInOrderWithBusTimes) {
  // Given a broker with one 1 Mbit/s bus and two client processes on it,
  // when both send 500 frames at the same time,
  // then each receives the other's 500 frames, in order, never its own, with increasing bus times
  // (paced: at least one frame time apart, since a transfer occupies the bus).
  const ExchangeCase c = GetParam();
  TempDir dir;
  BrokerProcess broker(dir, {"tcp://127.0.0.1:0", "unix://" + dir.File("b.sock")},
                       {c.paced ? "can0:1M" : "can0:1M:unpaced"});
  ASSERT_EQ(broker.endpoints().size(), 2u);
  const std::string endpoint =
      std::string(c.transport) == "tcp" ? broker.endpoints()[0] : broker.endpoints()[1];
  auto a = StartClient(dir, endpoint, "a");
  auto b = StartClient(dir, endpoint, "b");
  ASSERT_TRUE(a->WaitForPrefix("connected")) << a->Log();
  ASSERT_TRUE(b->WaitForPrefix("connected")) << b->Log();
  EXPECT_NE(a->Lines().back().find(c.paced ? " paced" : " unpaced"), std::string::npos) << a->Lines().back();

  constexpr std::size_t kFrames = 500;
  a->WriteLine("send 181 " + std::to_string(kFrames));
  b->WriteLine("send 182 " + std::to_string(kFrames));
  ASSERT_TRUE(a->WaitForPrefix("sent")) << a->Log();
  ASSERT_TRUE(b->WaitForPrefix("sent")) << b->Log();
  ASSERT_TRUE(WaitUntil([&] { return CountRx(*a) >= kFrames && CountRx(*b) >= kFrames; }))
      << "a got " << CountRx(*a) << ", b got " << CountRx(*b);

  for (const auto& [client, other_id] : {std::pair{a.get(), "182"}, std::pair{b.get(), "181"}}) {
    const auto frames = ReceivedFrames(*client);
    ASSERT_EQ(frames.size(), kFrames);
    for (std::size_t i = 0; i < frames.size(); ++i) {
      ASSERT_EQ(frames[i].id, other_id) << "frame " << i;
      ASSERT_EQ(frames[i].seq, i) << "frame " << i << ": order";
      ASSERT_GT(frames[i].time_ns, 0);
      if (i == 0) continue;
      const std::int64_t delta = frames[i].time_ns - frames[i - 1].time_ns;
      if (c.paced) {
        // The shortest possible transfer (DLC 0, no stuffing, 3 bits intermission) is 47 bits:
        // 47 us at 1 Mbit/s. These frames are longer still.
        ASSERT_GE(delta, 47'000) << "frame " << i;
      } else {
        ASSERT_GE(delta, 0) << "frame " << i;  // unpaced: submission times, never backwards
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Transports, BrokerExchange,
                         ::testing::Values(ExchangeCase{"tcp", true}, ExchangeCase{"unix", true},
                                           ExchangeCase{"tcp", false}, ExchangeCase{"unix", false}),
                         [](const auto& test_info) {
                           return std::string(test_info.param.transport) +
                                  (test_info.param.paced ? "Paced" : "Unpaced");
                         });

class BrokerRestart : public ::testing::TestWithParam<const char*> {};

TEST_P(BrokerRestart, ClientReconnectsWithBackoffAndSaysSo) {
  // Given a client attached to a broker,
  // when the broker is killed, stays away a while and comes back at the same endpoint,
  // then the client logs the loss and each retry with a growing delay, attaches again by itself,
  // and frames flow again.
  TempDir dir;
  const std::string endpoint = std::string(GetParam()) == "tcp"
                                   ? "tcp://127.0.0.1:" + std::to_string(FreeTcpPort())
                                   : "unix://" + dir.File("r.sock");
  auto broker = std::make_unique<BrokerProcess>(dir, std::vector<std::string>{endpoint},
                                                std::vector<std::string>{"can0"});
  auto a = StartClient(dir, endpoint, "a");
  ASSERT_TRUE(a->WaitForPrefix("connected")) << a->Log();

  broker->process().Signal(SIGKILL);
  ASSERT_TRUE(broker->process().Wait());
  ASSERT_TRUE(a->WaitForPrefix("disconnected")) << a->Log();
  // 100 ms after the loss, then 200, 400, ... while nobody listens.
  ASSERT_TRUE(WaitUntil([&] { return a->Log().find("retrying in 400 ms") != std::string::npos; }))
      << a->Log();
  const std::string log = a->Log();
  EXPECT_NE(log.find("broker connection lost: "), std::string::npos) << log;
  EXPECT_NE(log.find("; reconnecting in 100 ms"), std::string::npos) << log;
  EXPECT_NE(log.find("retrying in 200 ms"), std::string::npos) << log;

  broker = std::make_unique<BrokerProcess>(dir, std::vector<std::string>{endpoint},
                                           std::vector<std::string>{"can0"});
  ASSERT_TRUE(a->WaitForPrefix("connected")) << a->Log() << broker->Log();
  auto b = StartClient(dir, endpoint, "b");
  ASSERT_TRUE(b->WaitForPrefix("connected")) << b->Log();
  a->WriteLine("send 123 10");
  ASSERT_TRUE(a->WaitForPrefix("sent")) << a->Log();
  EXPECT_TRUE(WaitUntil([&] { return CountRx(*b) >= 10; })) << b->Log();
}

INSTANTIATE_TEST_SUITE_P(Transports, BrokerRestart, ::testing::Values("tcp", "unix"),
                         [](const auto& test_info) { return std::string(test_info.param); });

/// What a misbehaving connection got back before the broker closed it, decoded.
std::vector<wire::Message> Decode(const std::vector<std::uint8_t>& bytes) {
  wire::StreamDecoder decoder;
  decoder.Feed(bytes);
  std::vector<wire::Message> out;
  wire::Message m;
  while (decoder.Next(m) == wire::StreamDecoder::Result::kMessage)
    out.push_back(m);
  return out;
}

std::string Encoded(const std::function<void(wire::MessageWriter&)>& fill) {
  wire::MessageWriter w;
  fill(w);
  const auto bytes = w.Bytes();
  return std::string(bytes.begin(), bytes.end());
}

TEST(BrokerProtocolErrors, BadConnectionsAreClosedWithAReasonWhileOthersCarryOn) {
  // Given two clients exchanging frames,
  // when other connections send garbage, oversized or out-of-order messages, or a Hello the broker
  // cannot accept,
  // then each of those connections is told why and closed, the broker logs the reason, and the
  // two clients lose nothing.
  TempDir dir;
  BrokerProcess broker(dir, {"unix://" + dir.File("g.sock")}, {"can0:1M", "can1:125k"});
  const std::string endpoint = broker.endpoints().at(0);
  auto a = StartClient(dir, endpoint, "a");
  auto b = StartClient(dir, endpoint, "b");
  ASSERT_TRUE(a->WaitForPrefix("connected"));
  ASSERT_TRUE(b->WaitForPrefix("connected"));
  a->WriteLine("send 181 2000");
  b->WriteLine("send 182 2000");

  std::mt19937 rng(99);
  std::string random(4096, '\0');
  for (auto& ch : random)
    ch = static_cast<char>(rng());
  random[0] = '\x7F';  // a plausible length, so the body parser is reached

  wire::Hello old_version = wire::MakeHello("can0", "old");
  old_version.set_protocol_version(99);

  struct Case {
    const char* what;
    std::string bytes;
    std::string reason;  // in the reply and in the broker's log
    bool refusal;        // HelloReply{accepted: false} rather than Error
  };
  const std::vector<Case> cases = {
      {"random bytes", random, "protocol error: malformed message", false},
      {"an HTTP request", "GET / HTTP/1.1\r\nHost: broker\r\n\r\n" + std::string(100, ' '),
       "protocol error: malformed message: not a canfleet.wire.Envelope", false},
      {"an overlong length prefix", std::string(12, '\xFF'), "protocol error: malformed length prefix",
       false},
      {"2 MiB announced", std::string("\x80\x80\x80\x01", 4),
       "protocol error: message of 2097152 bytes exceeds the limit of 1048576", false},
      {"frames before Hello", Encoded([](wire::MessageWriter& w) { w.AddFrame(CanFrame::Data(0x100, {1})); }),
       "protocol error: FrameBatch before Hello", false},
      {"a second Hello", Encoded([](wire::MessageWriter& w) {
         w.AddHello(wire::MakeHello("can0", "twice"));
         w.AddHello(wire::MakeHello("can0", "twice"));
       }),
       "protocol error: second Hello", false},
      {"protocol version 99", Encoded([&](wire::MessageWriter& w) { w.AddHello(old_version); }),
       "protocol version 99 not supported: this broker speaks version " +
           std::to_string(wire::kProtocolVersion),
       true},
      {"an unknown bus", Encoded([](wire::MessageWriter& w) { w.AddHello(wire::MakeHello("can7", "lost")); }),
       "unknown bus can7 (this broker has: can0, can1)", true},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    RawConnection bad(endpoint);
    ASSERT_TRUE(bad.connected());
    bad.Send(c.bytes);
    const auto got = bad.ReadUntilClosed();
    ASSERT_TRUE(got.closed) << "the broker did not close the connection";
    const auto replies = Decode(got.bytes);
    ASSERT_FALSE(replies.empty());
    const wire::Message& last = replies.back();
    if (c.refusal) {
      ASSERT_EQ(last.type, wire::MessageType::kHelloReply);
      EXPECT_FALSE(last.envelope.hello_reply().accepted());
      EXPECT_EQ(last.envelope.hello_reply().reason(), c.reason);
    } else {
      ASSERT_EQ(last.type, wire::MessageType::kError);
      EXPECT_TRUE(last.envelope.error().reason().starts_with(c.reason)) << last.envelope.error().reason();
    }
    EXPECT_TRUE(WaitUntil([&] { return broker.Log().find(c.reason) != std::string::npos; })) << broker.Log();
  }

  ASSERT_TRUE(a->WaitForPrefix("sent")) << a->Log();
  ASSERT_TRUE(b->WaitForPrefix("sent")) << b->Log();
  ASSERT_TRUE(WaitUntil([&] { return CountRx(*a) >= 2000 && CountRx(*b) >= 2000; }));
  for (auto* client : {a.get(), b.get()}) {
    const auto frames = ReceivedFrames(*client);
    ASSERT_EQ(frames.size(), 2000u);
    for (std::size_t i = 0; i < frames.size(); ++i)
      ASSERT_EQ(frames[i].seq, i);
  }
  EXPECT_TRUE(broker.process().Running());
}

TEST(BrokerShutdown, SigtermDetachesClientsWithAReasonAndRemovesTheSocket) {
  // Given a broker on a Unix socket with one client,
  // when it gets SIGTERM,
  // then it exits 0, the client is told "broker shutting down" and starts reconnecting, and the
  // socket file is gone.
  TempDir dir;
  const std::string path = dir.File("s.sock");
  BrokerProcess broker(dir, {"unix://" + path}, {"can0"});
  auto a = StartClient(dir, "unix://" + path, "a");
  ASSERT_TRUE(a->WaitForPrefix("connected"));
  broker.process().Signal(SIGTERM);
  EXPECT_EQ(broker.process().Wait(), 0) << broker.Log();
  const auto lost = a->WaitForPrefix("disconnected");
  ASSERT_TRUE(lost) << a->Log();
  EXPECT_EQ(*lost, "disconnected the broker closed the connection: broker shutting down");
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_TRUE(WaitUntil([&] { return a->Log().find("reconnecting in 100 ms") != std::string::npos; }))
      << a->Log();
}

}  // namespace
}  // namespace canfleet::system_test
