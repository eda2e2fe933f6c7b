// Issue 6: topology errors, supervision (boot report, crash restart policy, no orphans) and the
// process faults (kill, restart, power-cycle with stored parameters kept), with real processes.
#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <fstream>
#include <iterator>

#include "tests/system/fleet/fleet_harness.hpp"

namespace canfleet::system_test {
namespace {

constexpr auto kLong = std::chrono::seconds(30);

constexpr const char* kTwoQuads = R"(
name: "fleet-test"
bus { name: "can0" bitrate: 500000 }
node { name: "quad-5" device: "quad-controller" node_id: 5 bus: "can0"
       heartbeat { producer_ms: 200 } restart { policy: ON_FAILURE backoff_ms: 200 } }
node { name: "quad-6" device: "quad-controller" node_id: 6 bus: "can0" }
)";

bool Alive(int pid) {
  return ::kill(pid, 0) == 0;
}

CliResult UpOn(const TempDir& dir, const std::string& name, const std::string& text) {
  std::ofstream(dir.File(name)) << text;
  return RunCanfleet({"up", dir.File(name), "--control", "tcp://127.0.0.1:0", "--listen", "tcp://127.0.0.1:0",
                      "--node-binary", PROGRAM_CANFLEET_NODE});
}

TEST(FleetTopologyErrors, SyntaxErrorIsRefusedWithFileLineAndColumn) {
  TempDir dir;
  const auto result =
      UpOn(dir, "broken.textproto", "name: \"fleet-test\"\nbus { name: \"can0\" }\nnode { nam: \"x\" }\n");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.err.find("broken.textproto:3:"), std::string::npos) << result.err;
}

TEST(FleetTopologyErrors, DuplicateNodeIdIsRefusedNamingTheField) {
  TempDir dir;
  const auto result = UpOn(dir, "dup.textproto", R"(name: "fleet-test"
bus { name: "can0" }
node { name: "a" device: "quad-controller" node_id: 5 bus: "can0" }
node { name: "b" device: "quad-controller" node_id: 5 bus: "can0" }
)");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.err.find("dup.textproto:4:"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("node_id"), std::string::npos) << result.err;
}

TEST(FleetSupervision, UpReportsBootedNodesAndDownLeavesNoProcess) {
  FleetUnderTest fleet(kTwoQuads);
  ASSERT_TRUE(fleet.WaitReady()) << fleet.Log();
  const auto status = fleet.Status();
  ASSERT_EQ(status.nodes_size(), 2);
  std::vector<int> pids;
  for (const auto& node : status.nodes()) {
    EXPECT_EQ(node.process(), "running") << node.name();
    EXPECT_TRUE(node.booted()) << node.name();
    EXPECT_TRUE(node.attached()) << node.name();
    EXPECT_EQ(node.controller(), "error-active");
    pids.push_back(node.pid());
  }
  const auto text = fleet.Cli({"status"});
  EXPECT_EQ(text.exit_code, 0);
  EXPECT_NE(text.out.find("quad-5"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("can0"), std::string::npos) << text.out;

  EXPECT_EQ(fleet.Cli({"down"}).exit_code, 0);
  EXPECT_EQ(fleet.process().Wait(kLong), 0);
  for (const int pid : pids)
    EXPECT_TRUE(WaitUntil([pid] { return !Alive(pid); }, kLong)) << "orphan node process " << pid;
}

TEST(FleetSupervision, KilledOrchestratorTakesItsNodesWithIt) {
  FleetUnderTest fleet(kTwoQuads);
  ASSERT_TRUE(fleet.WaitReady()) << fleet.Log();
  const auto pids = fleet.NodePids();
  ASSERT_EQ(pids.size(), 2u);
  fleet.process().Signal(SIGKILL);
  for (const int pid : pids)
    EXPECT_TRUE(WaitUntil([pid] { return !Alive(pid); }, kLong)) << "orphan node process " << pid;
}

TEST(FleetSupervision, CrashedNodeIsRestartedPerItsPolicy) {
  FleetUnderTest fleet(kTwoQuads);
  ASSERT_TRUE(fleet.WaitReady()) << fleet.Log();
  const auto before = fleet.Status();
  const int old_pid = fleet.Node(before, "quad-5")->pid();
  ::kill(old_pid, SIGKILL);  // a crash, as far as the orchestrator knows
  EXPECT_TRUE(WaitUntil(
      [&] {
        const auto status = fleet.Status();
        const auto* n = fleet.Node(status, "quad-5");
        return n->restarts() == 1 && n->pid() != old_pid && n->pid() > 0 && n->nmt_state() == "operational";
      },
      kLong))
      << fleet.Log();
  EXPECT_NE(fleet.Log().find("quad-5: process ended (signal 9"), std::string::npos);
  // quad-6 has policy never: a crash leaves it exited.
  const int six = fleet.Node(before, "quad-6")->pid();
  ::kill(six, SIGKILL);
  EXPECT_TRUE(WaitUntil(
      [&] {
        const auto status = fleet.Status();
        return fleet.Node(status, "quad-6")->process() == "exited";
      },
      kLong));
}

TEST(FleetProcessFaults, KillKeepsTheNodeDownUntilCleared) {
  FleetUnderTest fleet(kTwoQuads);
  ASSERT_TRUE(fleet.WaitReady()) << fleet.Log();
  ASSERT_EQ(fleet.Cli({"fault", "inject", "kill", "--node", "quad-5"}).exit_code, 0);
  EXPECT_TRUE(WaitUntil(
      [&] {
        const auto status = fleet.Status();
        const auto* n = fleet.Node(status, "quad-5");
        return n->process() == "killed" && !n->attached();
      },
      kLong));
  ASSERT_EQ(fleet.Cli({"fault", "clear", "--all"}).exit_code, 0);
  EXPECT_TRUE(WaitUntil(
      [&] {
        const auto status = fleet.Status();
        const auto* n = fleet.Node(status, "quad-5");
        return n->process() == "running" && n->booted() && n->nmt_state() == "operational";
      },
      kLong))
      << fleet.Log();
}

TEST(FleetProcessFaults, PowerCycleBootsAgainWithStoredParametersKept) {
  FleetUnderTest fleet(kTwoQuads);
  ASSERT_TRUE(fleet.WaitReady()) << fleet.Log();
  // CiA 301 §7.5.2.13: 1017h = 777 ms, then "save" (65766173h) into 1010h sub 1.
  ASSERT_EQ(fleet.Cli({"sdo", "write", "quad-6", "0x1017", "0", "u16", "777"}).exit_code, 0);
  const auto saved = fleet.Cli({"sdo", "write", "quad-6", "0x1010", "1", "u32", "0x65766173"});
  ASSERT_EQ(saved.exit_code, 0) << saved.err;
  const auto before = fleet.Status();
  ASSERT_GT(fleet.Node(before, "quad-6")->pid(), 0) << fleet.Log();
  const int old_pid = fleet.Node(before, "quad-6")->pid();
  ASSERT_EQ(fleet.Cli({"fault", "inject", "power-cycle", "--node", "quad-6"}).exit_code, 0);
  EXPECT_TRUE(WaitUntil(
      [&] {
        const auto status = fleet.Status();
        const auto* n = fleet.Node(status, "quad-6");
        return n->pid() > 0 && n->pid() != old_pid && n->booted() && n->nmt_state() == "operational";
      },
      kLong))
      << fleet.Log();
  EXPECT_EQ(fleet.SdoReadUnsigned("quad-6", "0x1017", 0, "u16"), 777u);
}

TEST(FleetProcessFaults, RestartStopsAndStartsTheProcess) {
  FleetUnderTest fleet(kTwoQuads);
  ASSERT_TRUE(fleet.WaitReady()) << fleet.Log();
  const auto before = fleet.Status();
  ASSERT_GT(fleet.Node(before, "quad-6")->pid(), 0) << fleet.Log();
  const int old_pid = fleet.Node(before, "quad-6")->pid();
  ASSERT_EQ(fleet.Cli({"fault", "inject", "restart", "--node", "quad-6"}).exit_code, 0);
  EXPECT_TRUE(WaitUntil(
      [&] {
        const auto status = fleet.Status();
        const auto* n = fleet.Node(status, "quad-6");
        return n->pid() > 0 && n->pid() != old_pid && n->booted();
      },
      kLong))
      << fleet.Log();
  EXPECT_NE(fleet.NodeLog("quad-6").find("shutting down"), std::string::npos);
}

TEST(FleetFrames, DumpAndCaptureShowTheBusTraffic) {
  FleetUnderTest fleet(kTwoQuads);
  ASSERT_TRUE(fleet.WaitReady()) << fleet.Log();
  // quad-5's heartbeat (705h, every 200 ms) in candump's log format.
  const auto dump = fleet.Cli({"dump", "can0", "--id", "0x705", "--count", "3"});
  ASSERT_EQ(dump.exit_code, 0) << dump.err;
  EXPECT_EQ(std::count(dump.out.begin(), dump.out.end(), '\n'), 3) << dump.out;
  EXPECT_NE(dump.out.find(" can0 705#05"), std::string::npos) << dump.out;

  // A relative file goes to the fleet's capture folder; the answer names where.
  const auto started_capture = fleet.Cli({"capture", "start", "--bus", "can0", "--file", "can0.pcap"});
  ASSERT_EQ(started_capture.exit_code, 0) << started_capture.err;
  const auto arrow = started_capture.out.find(" -> ");
  ASSERT_NE(arrow, std::string::npos) << started_capture.out;
  const std::string pcap = started_capture.out.substr(arrow + 4, started_capture.out.find('\n') - arrow - 4);
  EXPECT_NE(pcap.find("/captures/can0.pcap"), std::string::npos) << pcap;
  const double started = fleet.Status().uptime_s();
  ASSERT_TRUE(WaitUntil([&] { return fleet.Status().uptime_s() > started + 1.0; }, kLong));
  const auto stopped = fleet.Cli({"capture", "stop"});
  ASSERT_EQ(stopped.exit_code, 0) << stopped.err;
  std::ifstream in(pcap, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // 24-byte global header, then 32-byte records (bus/capture/pcap_writer.hpp): at least a few
  // heartbeats in a second.
  ASSERT_GE(bytes.size(), 24u + 3 * 32u) << stopped.out;
  EXPECT_EQ(static_cast<unsigned char>(bytes[20]), 227u);  // LINKTYPE_CAN_SOCKETCAN
}

// The broker endpoint the fleet's ready file names (written once the buses listen).
std::string BrokerEndpoint(const FleetUnderTest& fleet) {
  std::string broker;
  WaitUntil(
      [&] {
        std::ifstream in(fleet.dir().File("ready"));
        std::string key, value;
        while (in >> key >> value)
          if (key == "broker") broker = value;
        return !broker.empty();
      },
      kLong);
  return broker;
}

// Waits until the orchestrator reports `node` attached, booted and operational.
bool WaitAttachedAndOperational(const FleetUnderTest& fleet, const std::string& node) {
  return WaitUntil(
      [&] {
        const auto status = fleet.Status();
        const auto* n = fleet.Node(status, node);
        return n->attached() && n->booted() && n->nmt_state() == "operational";
      },
      kLong);
}

// A node started elsewhere (another host, a container) attaches by name: the orchestrator
// configures it after its boot-up like its own, and reaches its simulated I/O over its broker
// connection.
TEST(FleetSupervision, ExternalNodeAttachesByNameAndIsConfigured) {
  FleetUnderTest fleet(R"(
name: "fleet-test"
bus { name: "can0" bitrate: 500000 }
node { name: "quad-5" device: "quad-controller" node_id: 5 bus: "can0" }
node { name: "remote-8" device: "quad-controller" node_id: 8 bus: "can0" external: true
       heartbeat { producer_ms: 300 } }
)");
  const std::string broker = BrokerEndpoint(fleet);
  ASSERT_FALSE(broker.empty()) << fleet.Log();
  const auto before = fleet.Status();
  EXPECT_EQ(fleet.Node(before, "remote-8")->process(), "external");
  EXPECT_FALSE(fleet.Node(before, "remote-8")->attached());

  ChildProcess remote({PROGRAM_CANFLEET_NODE, "--device", "quad-controller", "--node-id", "8", "--name",
                       "remote-8", "--bus", "can0@" + broker, "--no-telemetry"},
                      fleet.dir().File("remote-8.log"));
  ASSERT_TRUE(fleet.WaitReady()) << fleet.Log();
  EXPECT_TRUE(WaitAttachedAndOperational(fleet, "remote-8")) << fleet.Log();
  EXPECT_EQ(fleet.SdoReadUnsigned("remote-8", "0x1017", 0, "u16"), 300u);  // configured by the orchestrator
  ASSERT_EQ(fleet.Cli({"io", "set", "remote-8", "IN1.voltage_mV", "2500"}).exit_code, 0);
  EXPECT_EQ(fleet.IoGet("remote-8", "IN1.voltage_mV"), "2500");
  // Its process is not ours to kill.
  EXPECT_EQ(fleet.Cli({"fault", "inject", "kill", "--node", "remote-8"}).exit_code, 1);
}

// An external node keeps running while the orchestrator restarts (its container restarted, say).
// It reconnects to the new broker without a boot-up; the new orchestrator sends it NMT reset
// communication (orchestrator/fleet/external_adoption.hpp), so that it boots up and is configured
// from the new topology like a node that had just started.
TEST(FleetSupervision, RestartedOrchestratorAdoptsARunningExternalNode) {
  const auto topology = [](int heartbeat_ms) {
    return R"(
name: "fleet-test"
bus { name: "can0" bitrate: 500000 }
node { name: "remote-8" device: "quad-controller" node_id: 8 bus: "can0" external: true
       heartbeat { producer_ms: )" +
           std::to_string(heartbeat_ms) + " } }\n";
  };
  TempDir dir;
  auto first = std::make_unique<FleetUnderTest>(topology(300));
  const std::string broker = BrokerEndpoint(*first);
  ASSERT_FALSE(broker.empty()) << first->Log();
  ChildProcess remote({PROGRAM_CANFLEET_NODE, "--device", "quad-controller", "--node-id", "8", "--name",
                       "remote-8", "--bus", "can0@" + broker, "--no-telemetry"},
                      dir.File("remote-8.log"));
  ASSERT_TRUE(first->WaitReady()) << first->Log();
  EXPECT_EQ(first->SdoReadUnsigned("remote-8", "0x1017", 0, "u16"), 300u);

  first.reset();  // SIGTERM: the orchestrator and its broker go, remote-8 keeps running
  ASSERT_TRUE(remote.Running()) << remote.Log();
  FleetUnderTest second(topology(700), broker);
  ASSERT_TRUE(second.WaitReady()) << second.Log() << remote.Log();
  EXPECT_NE(second.Log().find("without a boot-up"), std::string::npos) << second.Log();
  EXPECT_TRUE(remote.Running()) << "the same process was adopted, not a new one";
  EXPECT_EQ(second.SdoReadUnsigned("remote-8", "0x1017", 0, "u16"), 700u) << second.Log();
  EXPECT_TRUE(WaitAttachedAndOperational(second, "remote-8")) << second.Log();
}

// The topology's scenario runs on its own once the fleet is ready: inject, then clear by label.
TEST(FleetScenario, StepsInjectAndClearFaultsOnTime) {
  FleetUnderTest fleet(R"(
name: "fleet-test"
bus { name: "can0" bitrate: 250000 }
node { name: "quad-5" device: "quad-controller" node_id: 5 bus: "can0" heartbeat { producer_ms: 200 } }
node { name: "quad-6" device: "quad-controller" node_id: 6 bus: "can0"
       heartbeat { producer_ms: 200 consumer { node: "quad-5" timeout_ms: 1000 } } }
scenario { at_ms: 1000 inject { kind: HEARTBEAT_LOSS node: "quad-5" label: "hb" } }
scenario { at_ms: 4000 clear { label: "hb" } }
scenario { at_ms: 5000 nmt { action: NMT_START node: "quad-6" } }
)");
  ASSERT_TRUE(fleet.WaitReady()) << fleet.Log();
  // The orchestrator logs every EMCY it sees on the bus. Its log, not `last_emcy`, is the witness:
  // on a loaded machine the first status poll may come after the 0000h that follows the clear at
  // 4 s, and 8130h would then never be the last EMCY again.
  EXPECT_TRUE(WaitUntil([&] { return fleet.Log().find("quad-6: EMCY 8130h") != std::string::npos; }, kLong))
      << fleet.Log();
  EXPECT_TRUE(WaitUntil(
      [&] {
        control::FaultList list;
        ParseJson(fleet.Cli({"fault", "list", "--all", "--json"}).out, list);
        return list.faults_size() == 1 && list.faults(0).state() == "cleared" &&
               list.faults(0).spec().label() == "hb";
      },
      kLong));
  EXPECT_TRUE(WaitUntil(
      [&] {
        const auto status = fleet.Status();
        return fleet.Node(status, "quad-6")->nmt_state() == "operational" &&
               fleet.Node(status, "quad-6")->last_emcy().code() == 0x0000;
      },
      kLong))
      << fleet.Log();
}

}  // namespace
}  // namespace canfleet::system_test
