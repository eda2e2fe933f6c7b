// canfleet-node as a process (issue 5, "The node process": "logs through spdlog with the node's
// name in every line; SIGTERM shuts down cleanly; a lost broker connection reconnects; bad
// arguments: a clear message and a non-zero exit"; --list-devices, --help, --version;
// --state-dir keeps stored parameters).
#include <gtest/gtest.h>
#include <signal.h>

#include <cctype>
#include <filesystem>

#include "tests/system/node/node_system_support.hpp"

namespace canfleet::system_test {
namespace {

using namespace std::chrono_literals;
using canopen::SdoAbort;

std::vector<std::string> Quad5(const std::string& endpoint) {
  return {"--device", "quad-controller", "--node-id", "5", "--bus", "can0@" + endpoint};
}

bool HasLine(NodeProcess& node, const std::string& text) {
  for (const auto& line : node.LogLines())
    if (line.find(text) != std::string::npos) return true;
  return false;
}

std::size_t CountLines(NodeProcess& node, const std::string& text) {
  std::size_t n = 0;
  for (const auto& line : node.LogLines())
    n += line.find(text) != std::string::npos ? 1 : 0;
  return n;
}

/// Every line the node wrote (no control command was sent, so all are log lines, on whichever
/// stream) names the node: spdlog's "[time] [NAME] [level] text".
void ExpectNameInEveryLogLine(NodeProcess& node, const std::string& name) {
  const auto lines = node.AllLines();
  EXPECT_GE(lines.size(), 3u) << node.Output();
  for (const auto& line : lines)
    EXPECT_NE(line.find("[" + name + "]"), std::string::npos) << "log line without the node's name: " << line;
}

TEST(CanfleetNodeProcess, SigtermShutsDownCleanlyAndEveryLogLineNamesTheNode) {
  TempDir dir;
  BrokerProcess broker(dir, "tcp://127.0.0.1:0");
  BusMaster master(broker.endpoint());
  ASSERT_TRUE(master.WaitConnected());
  NodeProcess node(dir, "node", Quad5(broker.endpoint()));
  ASSERT_TRUE(master.WaitForFrame("705#00")) << node.Output();
  ASSERT_TRUE(WaitUntil([&] { return HasLine(node, "powered on"); })) << node.Output();

  node.process().Signal(SIGTERM);
  EXPECT_EQ(node.process().Wait(), 0) << node.Output();
  EXPECT_TRUE(HasLine(node, "signal 15: shutting down")) << node.Output();
  ExpectNameInEveryLogLine(node, "quad-controller@5");
}

TEST(CanfleetNodeProcess, ALostBrokerIsReconnectedAndTheHeartbeatReturns) {
  // Given a node with a 100 ms heartbeat (1017h set by SDO) on a broker at a fixed port,
  // when the broker is killed and later started again on the same port,
  // then the node logs the loss, reconnects by itself and its heartbeat reaches the new bus.
  TempDir dir;
  const std::string listen = "tcp://127.0.0.1:" + std::to_string(FreeTcpPort());
  auto broker = std::make_unique<BrokerProcess>(dir, listen);
  auto master = std::make_unique<BusMaster>(broker->endpoint());
  ASSERT_TRUE(master->WaitConnected());
  std::vector<std::string> args = Quad5(broker->endpoint());
  args.insert(args.end(), {"--name", "left-boom"});
  NodeProcess node(dir, "node", args);
  ASSERT_TRUE(master->WaitForFrame("705#00")) << node.Output();
  ASSERT_EQ(master->Write(5, 0x1017, 0, 100, 2), SdoAbort::kNone);
  ASSERT_TRUE(master->WaitForFrame("705#7F")) << node.Output();  // CiA 301 §7.2.8.3.2.1, pre-operational

  broker->process().Signal(SIGKILL);
  ASSERT_TRUE(broker->process().Wait());
  master.reset();
  EXPECT_TRUE(WaitUntil([&] { return HasLine(node, "broker connection lost"); })) << node.Output();
  EXPECT_TRUE(node.process().Running()) << node.Output();

  broker = std::make_unique<BrokerProcess>(dir, listen);
  master = std::make_unique<BusMaster>(broker->endpoint());
  ASSERT_TRUE(master->WaitConnected()) << broker->Log();
  EXPECT_TRUE(WaitUntil([&] { return CountLines(node, "connected to the broker") >= 2; })) << node.Output();
  // Still node 5, still pre-operational, still beating: the node did not restart.
  EXPECT_TRUE(master->WaitForFrame("705#7F")) << node.Output() << broker->Log();
  EXPECT_EQ(master->ReadUnsigned(5, 0x1017, 0), 100u);
  ExpectNameInEveryLogLine(node, "left-boom");
}

struct BadArguments {
  const char* what;
  std::vector<std::string> args;
  std::vector<std::string> message;  ///< words the message must contain
};

void PrintTo(const BadArguments& c, std::ostream* os) {
  *os << c.what;
}

class CanfleetNodeBadArguments : public ::testing::TestWithParam<BadArguments> {};

TEST_P(CanfleetNodeBadArguments, ExitWithCode2AndSayWhy) {
  const BadArguments& c = GetParam();
  TempDir dir;
  std::vector<std::string> argv = {PROGRAM_CANFLEET_NODE};
  argv.insert(argv.end(), c.args.begin(), c.args.end());
  const RunResult r = RunToCompletion(dir, argv);
  ASSERT_TRUE(r.status.has_value()) << c.what << ": still running";
  EXPECT_EQ(*r.status, 2) << c.what << "\nstderr: " << r.err << "\nstdout: " << r.out;
  for (const auto& word : c.message)
    EXPECT_NE(r.err.find(word), std::string::npos) << c.what << ": no '" << word << "' in stderr: " << r.err;
}

const std::string kBus = "can0@tcp://127.0.0.1:1";

INSTANTIATE_TEST_SUITE_P(
    Cases, CanfleetNodeBadArguments,
    ::testing::Values(
        BadArguments{"unknown device",
                     {"--device", "no-such-box", "--node-id", "5", "--bus", kBus},
                     {"unknown device", "no-such-box", "quad-controller"}},
        BadArguments{"node-ID 0",
                     {"--device", "quad-controller", "--node-id", "0", "--bus", kBus},
                     {"--node-id", "0"}},
        BadArguments{"node-ID 128",
                     {"--device", "quad-controller", "--node-id", "128", "--bus", kBus},
                     {"--node-id", "128"}},
        BadArguments{"no --bus", {"--device", "quad-controller", "--node-id", "5"}, {"--bus"}},
        BadArguments{"a bus without an endpoint",
                     {"--device", "quad-controller", "--node-id", "5", "--bus", "can0"},
                     {"--bus", "can0", "tcp://"}},
        BadArguments{"an endpoint that is not tcp or unix",
                     {"--device", "quad-controller", "--node-id", "5", "--bus", "can0@http://127.0.0.1:80"},
                     {"--bus", "http://127.0.0.1:80"}},
        BadArguments{"neither --device nor --eds", {"--node-id", "5", "--bus", kBus}, {"--device", "--eds"}},
        BadArguments{"an EDS file that does not exist",
                     {"--eds", "/nonexistent/vendor.eds", "--node-id", "5", "--bus", kBus},
                     {"--eds", "/nonexistent/vendor.eds"}},
        BadArguments{"an unknown option",
                     {"--device", "quad-controller", "--node-id", "5", "--bus", kBus, "--frobnicate"},
                     {"--frobnicate"}}),
    [](const auto& test_info) {
      std::string name;
      for (char ch : std::string(test_info.param.what))
        if (std::isalnum(static_cast<unsigned char>(ch))) name += ch;
      return name;
    });

TEST(CanfleetNodeProcess, VersionListDevicesAndHelpExitZero) {
  TempDir dir;
  const RunResult version = RunToCompletion(dir, {PROGRAM_CANFLEET_NODE, "--version"});
  EXPECT_EQ(version.status, 0) << version.err;
  EXPECT_TRUE(version.out.starts_with("canfleet-node ")) << version.out;

  const RunResult list = RunToCompletion(dir, {PROGRAM_CANFLEET_NODE, "--list-devices"});
  EXPECT_EQ(list.status, 0) << list.err;
  EXPECT_NE(list.out.find("quad-controller"), std::string::npos) << list.out;
  EXPECT_NE(list.out.find("AX020506"), std::string::npos) << list.out;

  const RunResult help = RunToCompletion(dir, {PROGRAM_CANFLEET_NODE, "--help"});
  EXPECT_EQ(help.status, 0) << help.err;
  for (const char* option :
       {"--device", "--eds", "--node-id", "--bus", "--state-dir", "--list-devices", "--version"})
    EXPECT_NE(help.out.find(option), std::string::npos) << option << " not in --help:\n" << help.out;
}

TEST(CanfleetNodeStorage, StoredParametersSurviveARestartWithTheSameStateDir) {
  // Manual §3.1.5 (1010h "save" = 65766173h stores the parameters), §3.1.6 (1011h "load" =
  // 64616F6Ch restores the defaults, valid after a reset); CiA 301 §7.5.2.13-14.
  TempDir dir;
  const std::string state = dir.File("state-quad5");
  BrokerProcess broker(dir, "tcp://127.0.0.1:0");
  BusMaster master(broker.endpoint());
  ASSERT_TRUE(master.WaitConnected());
  std::vector<std::string> args = Quad5(broker.endpoint());
  args.insert(args.end(), {"--state-dir", state});

  auto node = std::make_unique<NodeProcess>(dir, "first", args);
  ASSERT_TRUE(master.WaitForFrame("705#00")) << node->Output();
  EXPECT_EQ(master.ReadUnsigned(5, 0x1010, 1), 1u);  // saves on command
  ASSERT_EQ(master.Write(5, 0x1017, 0, 250, 2), SdoAbort::kNone);
  ASSERT_EQ(master.Write(5, 0x1010, 1, 0x65766173, 4), SdoAbort::kNone) << node->Output();
  ASSERT_EQ(master.Write(5, 0x1017, 0, 400, 2), SdoAbort::kNone);  // changed, not stored
  // Killed, not asked to stop: what was stored is on disk already.
  node->process().Signal(SIGKILL);
  ASSERT_TRUE(node->process().Wait());

  std::size_t mark = master.Frames().size();
  node = std::make_unique<NodeProcess>(dir, "second", args);
  ASSERT_TRUE(master.WaitForFrame("705#00", mark)) << node->Output();
  EXPECT_EQ(master.ReadUnsigned(5, 0x1017, 0), 250u) << node->Output();
  mark = master.Frames().size();
  EXPECT_TRUE(master.WaitForFrame("705#7F", mark)) << node->Output();  // beating from power-on

  // Restore the defaults; they apply at the next reset (NMT reset node).
  ASSERT_EQ(master.Write(5, 0x1011, 1, 0x64616F6C, 4), SdoAbort::kNone) << node->Output();
  EXPECT_EQ(master.ReadUnsigned(5, 0x1017, 0), 250u);
  mark = master.Frames().size();
  ASSERT_TRUE(master.Nmt(BusMaster::kNmtResetNode, 5));
  ASSERT_TRUE(master.WaitForFrame("705#00", mark)) << node->Output();
  EXPECT_EQ(master.ReadUnsigned(5, 0x1017, 0), 0u) << node->Output();
}

}  // namespace
}  // namespace canfleet::system_test
