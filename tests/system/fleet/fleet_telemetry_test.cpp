// Issue 7, "Tests", with real node processes: `canfleet up` runs 22 canfleet-node processes (20
// generic CiA 401 I/O nodes from topologies/eds/canfleet-dio16.eds and two Quad controllers) that
// publish over DDS. A reader in the test sees every node's status, the EMCY and the FaultEvent when
// a heartbeat loss is injected, and the recovery; a reader that joins late still gets the status of
// every node (NodeStatus is transient-local, telemetry/QOS.md).
//
// (tests/system/telemetry/fleet_telemetry_test.cpp covers the same at 127 nodes with synthetic
// publishers; this one proves the real processes and the orchestrator do it.)
#include <gtest/gtest.h>

#include <cstdlib>
#include <sstream>

#include "tests/system/fleet/fleet_harness.hpp"
#include "tests/system/telemetry/dds_monitor.hpp"

namespace canfleet::system_test {
namespace {

using namespace std::chrono_literals;
using canopen::NmtState;
using tools::EventKind;
using tools::FleetEvent;

constexpr int kGenericNodes = 20;
constexpr std::uint32_t kDomain = 77;  // no other test publishes here
/// 22 processes start, discover each other over loopback and get configured on a loaded machine.
constexpr auto kFleetPatience = 90s;

/// quad-2 consumes quad-1's heartbeat (Quad manual §4.2: a lost heartbeat is 8130h and the
/// fault state); the generic nodes only produce heartbeats.
std::string Topology() {
  std::ostringstream t;
  t << "name: \"telemetry-fleet\"\n"
    << "bus { name: \"can0\" bitrate: 500000 }\n"
    << "node { name: \"quad-1\" device: \"quad-controller\" node_id: 1 bus: \"can0\"\n"
    << "       heartbeat { producer_ms: 200 } }\n"
    << "node { name: \"quad-2\" device: \"quad-controller\" node_id: 2 bus: \"can0\"\n"
    << "       heartbeat { producer_ms: 200 consumer { node: \"quad-1\" timeout_ms: 1000 } } }\n";
  for (int i = 0; i < kGenericNodes; ++i) {
    const int id = 10 + i;
    t << "node { name: \"dio-" << id << "\" eds: \"" << CANFLEET_SOURCE_DIR
      << "/topologies/eds/canfleet-dio16.eds\" node_id: " << id << " bus: \"can0\"\n"
      << "       heartbeat { producer_ms: 1000 } }\n";
  }
  return t.str();
}

/// The fleet's processes publish on kDomain with the loopback configuration (set before the
/// harness starts `canfleet up`, which its children inherit).
std::string UseTestDomain() {
  ::setenv("CANFLEET_DDS_DOMAIN", std::to_string(kDomain).c_str(), 1);
  ::setenv("CANFLEET_DDS_CONFIG", CANFLEET_DDS_LOOPBACK_CONFIG, 1);
  return Topology();
}

bool IsOperational(const tools::NodeRow* row) {
  return row && row->alive && row->status.nmt_state == NmtState::kOperational;
}

TEST(FleetTelemetryRealNodes, EveryNodeTheEmcyTheFaultEventTheRecoveryAndLateJoiners) {
  FleetUnderTest fleet{UseTestDomain()};
  Monitor monitor(kDomain, CANFLEET_DDS_LOOPBACK_CONFIG);
  ASSERT_TRUE(fleet.WaitReady(kFleetPatience)) << fleet.Log();

  // Every node's status, each operational once the orchestrator has configured and started it.
  const int total = kGenericNodes + 2;
  ASSERT_TRUE(monitor.Until(
      [&] {
        int operational = 0;
        for (const auto& [key, row] : monitor.view().nodes())
          operational += IsOperational(&row) ? 1 : 0;
        return operational == total;
      },
      kFleetPatience))
      << monitor.view().nodes().size() << " nodes seen";
  EXPECT_EQ(monitor.Node("can0", 10)->status.device, "generic");
  EXPECT_EQ(monitor.Node("can0", 2)->status.device, "quad-controller");
  EXPECT_EQ(monitor.Node("can0", 2)->status.heartbeat_producer_ms, 200);

  // CiA 301 §7.2.8.3.2.2: a consumer starts monitoring at the first heartbeat it receives after
  // 1016h is written. quad-2 may have been started a few ms ago: wait until it watches quad-1.
  ASSERT_TRUE(monitor.Until(
      [&] {
        for (const auto& consumer : monitor.Node("can0", 2)->status.heartbeat_consumers)
          if (consumer.node_id == 1 && consumer.state == telemetry::HeartbeatConsumerState::kActive)
            return true;
        return false;
      },
      kFleetPatience));

  // A heartbeat loss: the orchestrator's FaultEvent, quad-2's EMCY 8130h (CiA 301 §7.2.7.2, Quad
  // manual §4.2) and its NMT change to pre-operational all arrive as DDS samples.
  const auto injected = fleet.Cli({"fault", "inject", "heartbeat-loss", "--node", "quad-1"});
  ASSERT_EQ(injected.exit_code, 0) << injected.err;
  EXPECT_TRUE(monitor.UntilEvent(
      [](const FleetEvent& e) {
        return e.kind == EventKind::kFault && e.fault && e.fault->kind == "heartbeat-loss" &&
               e.fault->action == telemetry::FaultAction::kInjected;
      },
      kFleetPatience));
  EXPECT_TRUE(monitor.UntilEvent(
      [](const FleetEvent& e) {
        return e.kind == EventKind::kEmcy && e.node_id == 2 && e.emcy && e.emcy->emcy.code == 0x8130;
      },
      kFleetPatience))
      << fleet.NodeLog("quad-2") << fleet.Log();
  EXPECT_TRUE(
      monitor.Until([&] { return monitor.Node("can0", 2)->status.nmt_state == NmtState::kPreOperational; },
                    kFleetPatience));
  EXPECT_TRUE(IsOperational(monitor.Node("can0", 1))) << "only the heartbeat frames are cut";

  // Recovery: the fault is cleared (FaultEvent), the consumer's error resets (EMCY 0000h) and the
  // master starts quad-2 again.
  ASSERT_EQ(fleet.Cli({"fault", "clear", "--all"}).exit_code, 0);
  EXPECT_TRUE(monitor.UntilEvent(
      [](const FleetEvent& e) {
        return e.kind == EventKind::kFault && e.fault && e.fault->action == telemetry::FaultAction::kCleared;
      },
      kFleetPatience));
  EXPECT_TRUE(monitor.UntilEvent(
      [](const FleetEvent& e) {
        return e.kind == EventKind::kEmcy && e.node_id == 2 && e.emcy && e.emcy->emcy.code == 0x0000;
      },
      kFleetPatience));
  ASSERT_EQ(fleet.Cli({"nmt", "start", "quad-2"}).exit_code, 0);
  EXPECT_TRUE(monitor.Until([&] { return IsOperational(monitor.Node("can0", 2)); }, kFleetPatience));

  // A reader that joins now gets every node's current status and the fault history at once.
  Monitor late(kDomain, CANFLEET_DDS_LOOPBACK_CONFIG);
  EXPECT_TRUE(late.Until([&] { return late.view().nodes().size() == static_cast<std::size_t>(total); },
                         kFleetPatience))
      << late.view().nodes().size() << " nodes seen by the late reader";
  EXPECT_TRUE(late.Until([&] { return IsOperational(late.Node("can0", 2)); }, kFleetPatience));
  EXPECT_TRUE(late.UntilEvent([](const FleetEvent& e) { return e.kind == EventKind::kFault && e.replay; },
                              kFleetPatience));
}

TEST(FleetTelemetryOptions, CanfleetUpPassesItsDdsOptionsToItsNodes) {
  // `canfleet up --dds-domain D --dds-config F` publishes there, and so do the nodes it starts
  // (they used to see only the environment, so a domain given on the command line left the nodes
  // on another). Nothing in the environment says where.
  ::unsetenv("CANFLEET_DDS_CONFIG");
  ::setenv("CANFLEET_DDS_DOMAIN", "76", 1);  // a decoy: the command line must win
  constexpr std::uint32_t kOptionDomain = 79;
  Monitor monitor(kOptionDomain, CANFLEET_DDS_LOOPBACK_CONFIG);
  FleetUnderTest fleet(
      "name: \"dds-options\"\n"
      "bus { name: \"can0\" bitrate: 500000 }\n"
      "node { name: \"quad-3\" device: \"quad-controller\" node_id: 3 bus: \"can0\" }\n",
      "tcp://127.0.0.1:0",
      {"--dds-domain", std::to_string(kOptionDomain), "--dds-config", CANFLEET_DDS_LOOPBACK_CONFIG});
  ASSERT_TRUE(fleet.WaitReady()) << fleet.Log();
  EXPECT_TRUE(monitor.Until([&] { return IsOperational(monitor.Node("can0", 3)); }, kFleetPatience))
      << "quad-3 not seen on DDS domain " << kOptionDomain;
  // The orchestrator's own BusStats are there too.
  EXPECT_TRUE(monitor.Until([&] { return monitor.view().buses().count("can0") == 1; }));
}

}  // namespace
}  // namespace canfleet::system_test
