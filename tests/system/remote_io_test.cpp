// Remote I/O (wire NodeRequest / NodeReply): the orchestrator's broker server sets and reads the
// simulated I/O of a real canfleet-node process over the node's own bus connection
// (design decision 5, "Simulated I/O is uniform"; node/process/remote_io.hpp).
#include <gtest/gtest.h>

#include <asio/io_context.hpp>
#include <optional>
#include <string>

#include "clock/asio_scheduler.hpp"
#include "orchestrator/broker/broker.hpp"
#include "orchestrator/transport/broker_server.hpp"
#include "tests/support/wire_text.hpp"
#include "tests/system/support/child_process.hpp"

namespace canfleet::system_test {
namespace {

using namespace std::chrono_literals;

class RemoteIo : public ::testing::Test {
 protected:
  RemoteIo() {
    broker_.AddBus({.name = "can0", .bitrate = 500'000});
    endpoint_ = server_.Listen(wire::Endpoint::Parse("unix://" + dir_.File("broker.sock"))).ToString();
  }

  bool RunUntil(const std::function<bool()>& condition, std::chrono::milliseconds timeout = kPatience) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (!condition()) {
      if (std::chrono::steady_clock::now() >= deadline) return false;
      io_.restart();
      io_.run_for(5ms);
    }
    return true;
  }

  bool Attached(const std::string& name) {
    for (const auto& port : broker_.Ports("can0"))
      if (port.name == name) return true;
    return false;
  }

  /// One request, run to its answer.
  std::optional<wire::NodeReply> Ask(const std::string& node, const wire::NodeRequest& request) {
    bool done = false;
    std::optional<wire::NodeReply> reply;
    server_.RequestNode("can0", node, request, [&](std::optional<wire::NodeReply> r) {
      reply = std::move(r);
      done = true;
    });
    EXPECT_TRUE(RunUntil([&] { return done; }));
    return reply;
  }

  static wire::NodeRequest Set(std::uint64_t id, const std::string& name, const std::string& value) {
    wire::NodeRequest r;
    r.set_request_id(id);
    r.mutable_io_set()->set_name(name);
    r.mutable_io_set()->set_value(value);
    return r;
  }
  static wire::NodeRequest Get(std::uint64_t id, const std::string& name) {
    wire::NodeRequest r;
    r.set_request_id(id);
    r.mutable_io_get()->set_name(name);
    return r;
  }

  TempDir dir_;
  asio::io_context io_;
  AsioScheduler scheduler_{io_};
  broker::Broker broker_{scheduler_};
  transport::BrokerServer server_{io_, broker_};
  std::string endpoint_;
};

// Given a quad controller process attached as quad-5, when the orchestrator sets IN1.voltage_mV
// to 3000 over the wire, then reading it back gives 3000 mV (an input); an unknown signal and an
// out-of-range value are refused with SimulatedIo's one-line reason and change nothing.
TEST_F(RemoteIo, SetAndReadBackAnInputOfARealNodeProcess) {
  ChildProcess node({PROGRAM_CANFLEET_NODE, "--device", "quad-controller", "--node-id", "5", "--bus",
                     "can0@" + endpoint_, "--name", "quad-5", "--log-level", "warn"},
                    dir_.File("node.log"));
  ASSERT_TRUE(RunUntil([&] { return Attached("quad-5"); })) << node.Log();

  auto reply = Ask("quad-5", Set(1, "IN1.voltage_mV", "3000"));
  ASSERT_TRUE(reply) << node.Log();
  EXPECT_EQ(reply->request_id(), 1u);
  EXPECT_EQ(reply->error(), "");
  ASSERT_EQ(reply->values_size(), 1);
  EXPECT_EQ(reply->values(0).value(), "3000");

  reply = Ask("quad-5", Get(2, "IN1.voltage_mV"));
  ASSERT_TRUE(reply);
  EXPECT_EQ(test::WireText(*reply),
            R"(request_id: 2 values { name: "IN1.voltage_mV" value: "3000" unit: "mV" input: true })");

  reply = Ask("quad-5", Set(3, "IN9.voltage_mV", "3000"));
  ASSERT_TRUE(reply);
  EXPECT_EQ(reply->error(),
            "no signal IN9.voltage_mV; nearest: IN1.voltage_mV, IN2.voltage_mV, IN3.voltage_mV");
  EXPECT_TRUE(reply->unknown_signal());
  EXPECT_EQ(reply->nearest_size(), 3);
  EXPECT_EQ(reply->values_size(), 0);

  reply = Ask("quad-5", Get(4, "IN9.voltage_mV"));
  ASSERT_TRUE(reply);
  EXPECT_EQ(reply->error(),
            "no signal IN9.voltage_mV; nearest: IN1.voltage_mV, IN2.voltage_mV, IN3.voltage_mV");
  EXPECT_TRUE(reply->unknown_signal());
  EXPECT_EQ(reply->nearest_size(), 3);

  reply = Ask("quad-5", Set(5, "IN1.voltage_mV", "40000"));
  ASSERT_TRUE(reply);
  EXPECT_EQ(reply->error(), "IN1.voltage_mV: 40000 is out of range 0..36000 mV");

  // Every signal: AIN1 still at 3000, and outputs are listed as such.
  reply = Ask("quad-5", Get(6, ""));
  ASSERT_TRUE(reply);
  EXPECT_EQ(reply->error(), "");
  bool saw_ain1 = false, saw_output = false;
  for (const auto& v : reply->values()) {
    if (v.name() == "IN1.voltage_mV") saw_ain1 = v.value() == "3000" && v.input();
    if (!v.input()) saw_output = true;
  }
  EXPECT_TRUE(saw_ain1);
  EXPECT_TRUE(saw_output);
  EXPECT_GT(reply->values_size(), 10);

  // A node that is gone is not waited for.
  node.Signal(SIGKILL);
  ASSERT_TRUE(RunUntil([&] { return !Attached("quad-5"); }));
  EXPECT_FALSE(Ask("quad-5", Get(7, "")));
}

}  // namespace
}  // namespace canfleet::system_test
