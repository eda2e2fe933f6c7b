// Issue 7 with the real processes: canfleet-broker and two `canfleet-node --device quad-controller`
// publish over DDS (loopback configuration), and a FleetReader in the test, through the model the
// tools use (FleetView), sees
//  - both nodes with their NMT state (the same the node answers to `nmt` on its stdin), booted
//    into pre-operational, then operational after an NMT start from the master's port,
//  - an input change in a node's IoSnapshot (`set IN1.voltage_mV 3300` on its stdin),
//  - the EMCY of a load fault (Quad §4.1: a short on DOUT is FF02h after the 300Bh delay, 1 s) and
//    1001h in the node's status, then the error reset when the load is repaired,
//  - the BusStats of the broker's bus (its two ports, frames counted),
//  - a node leave (disposed) when its process gets SIGTERM, while the other stays,
//  - the bus's BusStats go when the broker gets SIGTERM.
// The master's port is a canfleet-bus-client attached first: a node alone on a bus gets no ACK for
// its boot-up, goes error passive and reports it (EMCY 8120h, 1001h), as on a real bus.
// Deadlines are generous: DDS discovery over unicast loopback on a loaded 2-core machine takes
// seconds.
#include <gtest/gtest.h>
#include <signal.h>

#include <filesystem>
#include <fstream>
#include <memory>

#include "telemetry/fleet_reader.hpp"
#include "tests/system/support/child_process.hpp"
#include "tools/telemetry/fleet_view.hpp"

namespace canfleet::system_test {
namespace {

using namespace std::chrono_literals;
using telemetry::ControllerState;
using telemetry::NmtState;
using tools::EventKind;
using tools::FleetEvent;

constexpr std::uint32_t kDomain = 92;
constexpr auto kDdsPatience = 60s;
constexpr const char* kBus = "tel0";

std::vector<std::string> DdsArgs() {
  return {"--dds-domain", std::to_string(kDomain), "--dds-config", CANFLEET_DDS_LOOPBACK_CONFIG};
}

/// The test's monitor: a FleetReader on every topic, feeding the tools' FleetView.
class Monitor {
 public:
  Monitor()
      : participant_({.domain_id = kDomain, .config_file = CANFLEET_DDS_LOOPBACK_CONFIG}),
        reader_(participant_,
                {.node_status = [this](const auto& s, const auto& m) { view_.Apply(s, m, &events_); },
                 .emcy = [this](const auto& s, const auto& m) { view_.Apply(s, m, &events_); },
                 .io = [this](const auto& s, const auto& m) { view_.Apply(s, m, &events_); },
                 .bus_stats = [this](const auto& s, const auto& m) { view_.Apply(s, m, &events_); },
                 .fault = {}}) {}

  bool Until(const std::function<bool()>& condition, std::chrono::milliseconds timeout = kDdsPatience) {
    return WaitUntil(
        [&] {
          reader_.Poll();
          return condition();
        },
        timeout);
  }
  const tools::NodeRow* Node(std::uint8_t id) const {
    const auto it = view_.nodes().find({kBus, id});
    return it == view_.nodes().end() ? nullptr : &it->second;
  }
  std::optional<double> Input(std::uint8_t id, const std::string& name) const {
    const auto* row = Node(id);
    if (!row || !row->io) return std::nullopt;
    for (const auto& value : row->io->inputs)
      if (value.name == name) return value.value;
    return std::nullopt;
  }
  const FleetEvent* Emcy(std::uint8_t id, std::uint16_t code) const {
    for (const auto& e : events_)
      if (e.kind == EventKind::kEmcy && e.node_id == id && e.emcy->emcy.code == code) return &e;
    return nullptr;
  }
  const std::optional<telemetry::BusStatsSample>* Bus() const {
    const auto it = view_.buses().find(kBus);
    return it == view_.buses().end() ? nullptr : &it->second.stats;
  }
  /// What the monitor knows, for failure messages.
  std::string Describe() const {
    std::string out = std::to_string(view_.nodes().size()) + " node(s):";
    for (const auto& [key, row] : view_.nodes()) {
      out += " " + key.bus + "#" + std::to_string(key.node_id) + "=" +
             telemetry::StateName(row.status.nmt_state) + (row.alive ? "" : "(gone)");
    }
    return out + ", " + std::to_string(events_.size()) + " event(s)";
  }

 private:
  telemetry::Participant participant_;
  tools::FleetView view_{std::chrono::system_clock::now()};
  std::vector<FleetEvent> events_;
  telemetry::FleetReader reader_;
};

class NodeTelemetryProcesses : public ::testing::Test {
 protected:
  void StartBroker() {
    const std::string ready = dir_.File("broker.ready");
    std::vector<std::string> argv = {
        PROGRAM_CANFLEET_BROKER, "--bus", std::string(kBus) + ":500k", "--listen", "tcp://127.0.0.1:0",
        "--ready-file",          ready,   "--telemetry-period",        "0.5"};
    for (auto& a : DdsArgs())
      argv.push_back(a);
    broker_ = std::make_unique<ChildProcess>(argv, dir_.File("broker.log"));
    ASSERT_TRUE(WaitUntil([&] { return std::filesystem::exists(ready) || !broker_->Running(); }))
        << broker_->Log();
    std::ifstream in(ready);
    std::getline(in, endpoint_);
    ASSERT_FALSE(endpoint_.empty()) << broker_->Log();
  }

  /// The master's port: acknowledges the nodes' frames and sends what the test tells it.
  void StartMaster() {
    master_ = std::make_unique<ChildProcess>(
        std::vector<std::string>{PROGRAM_CANFLEET_BUS_CLIENT, "--connect", endpoint_, "--bus", kBus, "--name",
                                 "master", "--stdin", "--quiet"},
        dir_.File("master.log"));
    ASSERT_TRUE(master_->WaitForPrefix("connected")) << master_->Log();
  }

  std::unique_ptr<ChildProcess> StartNode(int id) {
    std::vector<std::string> argv = {PROGRAM_CANFLEET_NODE,
                                     "--device",
                                     "quad-controller",
                                     "--node-id",
                                     std::to_string(id),
                                     "--bus",
                                     std::string(kBus) + "@" + endpoint_,
                                     "--stdin-control"};
    for (auto& a : DdsArgs())
      argv.push_back(a);
    return std::make_unique<ChildProcess>(argv, dir_.File("node" + std::to_string(id) + ".log"));
  }

  /// Sends a stdin-control command and waits for its "ok".
  static void Command(ChildProcess& node, const std::string& line) {
    node.WriteLine(line);
    ASSERT_TRUE(node.WaitForPrefix("ok")) << line << "\n" << node.Log();
  }

  TempDir dir_;
  std::string endpoint_;
  std::unique_ptr<ChildProcess> broker_;
  std::unique_ptr<ChildProcess> master_;
};

TEST_F(NodeTelemetryProcesses, BrokerAndTwoQuadNodesPublishStatusIoEmcyBusStatsAndLeaving) {
  Monitor monitor;
  StartBroker();
  StartMaster();
  auto node5 = StartNode(5);
  auto node6 = StartNode(6);

  // Both nodes, booted (CiA 301 §7.3.2: boot-up into pre-operational), and their NMT state is the
  // one the node itself reports.
  ASSERT_TRUE(monitor.Until([&] {
    for (const std::uint8_t id : {std::uint8_t{5}, std::uint8_t{6}}) {
      const auto* row = monitor.Node(id);
      if (!row || row->status.nmt_state != NmtState::kPreOperational) return false;
    }
    return true;
  })) << monitor.Describe()
      << "\n"
      << node5->Log();
  for (const std::uint8_t id : {std::uint8_t{5}, std::uint8_t{6}}) {
    const auto& s = monitor.Node(id)->status;
    EXPECT_EQ(s.device, "quad-controller");
    EXPECT_EQ(s.controller_state, ControllerState::kErrorActive);
    EXPECT_EQ(s.error_register, 0);
  }
  node5->WriteLine("nmt");
  EXPECT_TRUE(node5->WaitForPrefix("pre-operational")) << node5->Log();

  // NMT start all (000#0100, CiA 301 §7.2.8.3.1.1): both statuses follow.
  master_->WriteLine("frame 000#0100");
  ASSERT_TRUE(monitor.Until([&] {
    return monitor.Node(5)->status.nmt_state == NmtState::kOperational &&
           monitor.Node(6)->status.nmt_state == NmtState::kOperational;
  })) << monitor.Describe();
  node6->WriteLine("nmt");
  EXPECT_TRUE(node6->WaitForPrefix("operational")) << node6->Log();

  // The simulated I/O: an input set on node 5's stdin reaches its IoSnapshot.
  ASSERT_TRUE(monitor.Until([&] {
    return monitor.Input(5, "IN1.voltage_mV") == 2500.0 && monitor.Input(6, "IN1.voltage_mV") == 2500.0;
  })) << monitor.Describe();
  Command(*node5, "set IN1.voltage_mV 3300");
  ASSERT_TRUE(monitor.Until([&] { return monitor.Input(5, "IN1.voltage_mV") == 3300.0; }))
      << monitor.Describe();
  EXPECT_EQ(monitor.Input(6, "IN1.voltage_mV"), 2500.0);

  // A load fault on node 6 (Quad §4.1): DOUT shorted → EMCY FF02h, 1001h bit 0, channel 05h,
  // description 02h in the manufacturer bytes.
  Command(*node6, "set OUT5.load short");
  ASSERT_TRUE(monitor.Until([&] {
    const auto& status = monitor.Node(6)->status;
    return monitor.Emcy(6, 0xFF02) != nullptr && status.last_emcy && status.last_emcy->code == 0xFF02;
  })) << monitor.Describe();
  EXPECT_EQ(monitor.Node(6)->status.error_register, 0x01);
  const auto& emcy = monitor.Emcy(6, 0xFF02)->emcy->emcy;
  EXPECT_EQ(emcy.error_register, 0x01);
  EXPECT_EQ(emcy.manufacturer, (std::array<std::uint8_t, 5>{0x05, 0x02, 0x00, 0x00, 0x00}));
  EXPECT_EQ(monitor.Emcy(5, 0xFF02), nullptr);
  // Repaired: the error reset EMCY (0000h) and 1001h back to 0.
  Command(*node6, "set OUT5.load nominal");
  ASSERT_TRUE(monitor.Until([&] {
    return monitor.Emcy(6, 0x0000) != nullptr && monitor.Node(6)->status.error_register == 0;
  })) << monitor.Describe();

  // The broker's BusStats: the bus, its bitrate and the three ports; the traffic of two operational
  // Quads (their TPDOs' 100 ms event timers) counted and ranked.
  ASSERT_TRUE(monitor.Until([&] {
    const auto* stats = monitor.Bus();
    return stats && *stats && (*stats)->node_count == 3 && (*stats)->frames_total >= 10 &&
           (*stats)->frames_per_second > 0 && !(*stats)->top_cob_ids.empty();
  })) << monitor.Describe();
  EXPECT_EQ((*monitor.Bus())->bitrate, 500000u);
  EXPECT_EQ((*monitor.Bus())->mode, "realtime");

  // SIGTERM: node 5 shuts down cleanly and is seen leaving (disposed); node 6 stays.
  node5->Signal(SIGTERM);
  EXPECT_EQ(node5->Wait(kDdsPatience), std::optional<int>(0)) << node5->Log();
  ASSERT_TRUE(monitor.Until([&] { return !monitor.Node(5)->alive; })) << monitor.Describe();
  EXPECT_TRUE(monitor.Node(5)->disposed);
  EXPECT_TRUE(monitor.Node(6)->alive);
  // ... and the broker sees its port go.
  ASSERT_TRUE(monitor.Until([&] { return *monitor.Bus() && (*monitor.Bus())->node_count == 2; }))
      << monitor.Describe();

  // The broker's SIGTERM disposes its bus's BusStats.
  broker_->Signal(SIGTERM);
  EXPECT_EQ(broker_->Wait(kDdsPatience), std::optional<int>(0)) << broker_->Log();
  ASSERT_TRUE(monitor.Until([&] { return !*monitor.Bus(); })) << monitor.Describe();
}

// --no-telemetry: the node runs as before and publishes nothing.
TEST_F(NodeTelemetryProcesses, NoTelemetryPublishesNothing) {
  Monitor monitor;
  StartBroker();
  std::vector<std::string> argv = {PROGRAM_CANFLEET_NODE,
                                   "--device",
                                   "quad-controller",
                                   "--node-id",
                                   "7",
                                   "--bus",
                                   std::string(kBus) + "@" + endpoint_,
                                   "--stdin-control",
                                   "--no-telemetry"};
  for (auto& a : DdsArgs())
    argv.push_back(a);
  ChildProcess node(argv, dir_.File("node7.log"));
  // The broker's BusStats (same domain, same configuration) arrive, so the monitor is matched.
  ASSERT_TRUE(monitor.Until([&] {
    const auto* stats = monitor.Bus();
    return stats && *stats && (*stats)->node_count == 1;
  })) << monitor.Describe();
  // The node booted (it answers "initialising" until its port is connected).
  ASSERT_TRUE(WaitUntil(
      [&] {
        node.WriteLine("nmt");
        return node.WaitForPrefix("pre-operational", 1s).has_value();
      },
      kDdsPatience))
      << node.Log();
  // A few of the node's would-be periods later, still no node.
  EXPECT_FALSE(monitor.Until([&] { return monitor.Node(7) != nullptr; }, 3s)) << monitor.Describe();
}

}  // namespace
}  // namespace canfleet::system_test
