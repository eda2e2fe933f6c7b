// canfleet-node's telemetry wiring (node/process/node_telemetry_wiring.hpp): a Quad controller on a
// loopback bus with simulated time, its telemetry read back over real DDS by a FleetReader. The
// node's side runs on simulated time; only DDS delivery is real time (bounded waits).
#include <gtest/gtest.h>

#include "bus/loopback_bus.hpp"
#include "node/devices/device_node.hpp"
#include "node/devices/quad_controller/quad_controller.hpp"
#include "node/process/node_telemetry_wiring.hpp"
#include "telemetry/fleet_reader.hpp"
#include "test_dds.hpp"
#include "tests/support/bus_probe.hpp"
#include "tools/telemetry/fleet_view.hpp"

namespace canfleet::node {
namespace {

using namespace std::chrono_literals;
using telemetry::testing::Eventually;
using telemetry::testing::TestDds;

/// Everything a monitor sees, through the model the tools use.
struct Monitor {
  explicit Monitor(const telemetry::Participant& participant)
      : reader(participant,
               {.node_status = [this](const auto& s, const auto& m) { view.Apply(s, m, &events); },
                .emcy = [this](const auto& s, const auto& m) { view.Apply(s, m, &events); },
                .io = [this](const auto& s, const auto& m) { view.Apply(s, m, &events); },
                .bus_stats = {},
                .fault = {}}) {}
  bool Until(const std::function<bool()>& condition) {
    return Eventually([&] {
      reader.Poll();
      return condition();
    });
  }
  const tools::NodeRow* Node(std::uint8_t id) const {
    const auto it = view.nodes().find({"tcan0", id});
    return it == view.nodes().end() ? nullptr : &it->second;
  }
  std::optional<double> Input(std::uint8_t id, const std::string& name) const {
    const auto* row = Node(id);
    if (!row || !row->io) return std::nullopt;
    for (const auto& v : row->io->inputs)
      if (v.name == name) return v.value;
    return std::nullopt;
  }
  bool HasEmcy(std::uint16_t code) const {
    return std::any_of(events.begin(), events.end(), [&](const tools::FleetEvent& e) {
      return e.kind == tools::EventKind::kEmcy && e.emcy->emcy.code == code;
    });
  }

  tools::FleetView view{std::chrono::system_clock::now()};
  std::vector<tools::FleetEvent> events;
  telemetry::FleetReader reader;
};

class NodeTelemetryWiringTest : public ::testing::Test {
 protected:
  static constexpr std::uint8_t kNodeId = 5;

  explicit NodeTelemetryWiringTest(std::uint32_t domain = 25, std::uint8_t node_id = kNodeId)
      : settings_{.enabled = true, .dds = TestDds(domain), .period = 1000ms},
        participant_(settings_.dds),
        monitor_(participant_),
        node_port_(bus_.Attach("quad")),
        master_(bus_, "master") {
    wiring_ = std::make_unique<NodeTelemetryWiring>(settings_);
    devices::NodeSettings node_settings{{devices::PortSettings{node_id, 4}}, {}, std::nullopt, {}};
    node_settings.hooks = wiring_->Hooks();
    node_ = std::make_unique<devices::DeviceNode>(std::make_unique<devices::QuadController>(), scheduler_,
                                                  std::vector<BusPort*>{&node_port_}, node_settings);
    wiring_->Attach(*node_, scheduler_, {"tcan0"});
    node_->Start();
  }

  TelemetrySettings settings_;
  telemetry::Participant participant_;
  Monitor monitor_;
  SimulatedScheduler scheduler_;
  LoopbackBus bus_;
  LoopbackPort& node_port_;
  canfleet::test::BusProbe master_;
  std::unique_ptr<NodeTelemetryWiring> wiring_;
  std::unique_ptr<devices::DeviceNode> node_;
};

// The status carries the identity and the NMT state as the node boots (CiA 301 §7.3.2: boot-up
// into pre-operational) and follows an NMT start (000#0105) at once, not at the next period.
TEST_F(NodeTelemetryWiringTest, StatusFollowsTheNmtState) {
  ASSERT_TRUE(monitor_.Until([&] {
    return monitor_.Node(kNodeId) &&
           monitor_.Node(kNodeId)->status.nmt_state == canopen::NmtState::kPreOperational;
  }));
  const auto& s = monitor_.Node(kNodeId)->status;
  EXPECT_EQ(s.device, "quad-controller");
  EXPECT_EQ(s.controller_state, ControllerState::kErrorActive);
  EXPECT_EQ(s.error_register, 0);
  EXPECT_EQ(s.publish_period, 1000ms);

  master_.Send("000#0105");
  scheduler_.Advance(1ms);
  ASSERT_TRUE(monitor_.Until(
      [&] { return monitor_.Node(kNodeId)->status.nmt_state == canopen::NmtState::kOperational; }));
}

// Design decision 5: the simulated I/O, with names and units, and every change of an input.
TEST_F(NodeTelemetryWiringTest, IoSnapshotCarriesTheSimulatedIoAndItsChanges) {
  ASSERT_TRUE(monitor_.Until([&] { return monitor_.Input(kNodeId, "IN1.voltage_mV") == 2500.0; }));
  const auto& io = *monitor_.Node(kNodeId)->io;
  EXPECT_EQ(io.inputs.size() + io.outputs.size(), node_->io().Signals().size());
  EXPECT_EQ(io.inputs[0], (telemetry::IoValueSample{"IN1.voltage_mV", 2500.0, "mV"}));

  ASSERT_TRUE(node_->io().SetNumber("IN1.voltage_mV", 3100).ok());
  ASSERT_TRUE(monitor_.Until([&] { return monitor_.Input(kNodeId, "IN1.voltage_mV") == 3100.0; }));
}

// Quad §4.1: a short on DOUT is FF02h (channel 05h, description 02h) after the 300Bh sub 5 delay
// (1000 ms); the EMCY is published with its bytes and 1001h bit 0 reaches the status.
TEST_F(NodeTelemetryWiringTest, EveryEmcySentIsPublishedWithTheStatusItChanged) {
  ASSERT_TRUE(node_->io().SetEnum("OUT5.load", "short").ok());
  scheduler_.Advance(1100ms);
  ASSERT_EQ(master_.Take().empty(), false);
  ASSERT_TRUE(monitor_.Until([&] { return monitor_.HasEmcy(0xFF02); }));
  const auto emcy = std::find_if(monitor_.events.begin(), monitor_.events.end(), [](const auto& e) {
    return e.kind == tools::EventKind::kEmcy && e.emcy->emcy.code == 0xFF02;
  });
  EXPECT_EQ(emcy->node_id, kNodeId);
  EXPECT_EQ(emcy->emcy->emcy.error_register, 0x01);
  EXPECT_EQ(emcy->emcy->emcy.manufacturer, (std::array<std::uint8_t, 5>{0x05, 0x02, 0x00, 0x00, 0x00}));
  ASSERT_TRUE(monitor_.Until([&] {
    const auto* row = monitor_.Node(kNodeId);
    return row && row->status.error_register == 0x01 && row->status.last_emcy &&
           row->status.last_emcy->code == 0xFF02;
  }));

  // Repaired: the error reset (0000h) and 1001h back to 0.
  ASSERT_TRUE(node_->io().SetEnum("OUT5.load", "nominal").ok());
  scheduler_.Advance(20ms);
  ASSERT_TRUE(monitor_.Until(
      [&] { return monitor_.HasEmcy(0x0000) && monitor_.Node(kNodeId)->status.error_register == 0; }));
}

// ISO 11898-1 fault confinement as the port reports it: state and counters in the status, and the
// stack's EMCY 8120h (CiA 301 table 21, CAN in error passive mode).
TEST_F(NodeTelemetryWiringTest, ControllerStateAndCountersFollowThePort) {
  master_.Send("000#0105");
  scheduler_.Advance(1ms);
  node_port_.SetControllerState({ControllerState::kErrorPassive, 136, 3});
  ASSERT_TRUE(monitor_.Until([&] {
    const auto* row = monitor_.Node(kNodeId);
    return row && row->status.controller_state == ControllerState::kErrorPassive && row->status.tec == 136 &&
           row->status.rec == 3 && monitor_.HasEmcy(0x8120);
  }));
  node_port_.SetControllerState({ControllerState::kErrorActive, 0, 0});
  ASSERT_TRUE(monitor_.Until([&] {
    return monitor_.Node(kNodeId)->status.controller_state == ControllerState::kErrorActive &&
           monitor_.Node(kNodeId)->status.tec == 0;
  }));
}

// 1016h consumers and 1017h producer time, read from the dictionary at the next sample.
TEST_F(NodeTelemetryWiringTest, HeartbeatProducerAndConsumersAreSampledEveryPeriod) {
  master_.Send("605#2B17100064000000");  // 1017h = 100 ms
  master_.Send("605#23161001F4010100");  // 1016h sub 1: node 1, 500 ms
  scheduler_.Advance(1ms);
  master_.Send("701#05");  // node 1 operational: monitoring starts
  scheduler_.Advance(1000ms);
  ASSERT_TRUE(monitor_.Until([&] {
    const auto* row = monitor_.Node(kNodeId);
    return row && row->status.heartbeat_producer_ms == 100 && row->status.heartbeat_consumers.size() == 1;
  }));
  const auto consumer = monitor_.Node(kNodeId)->status.heartbeat_consumers[0];
  EXPECT_EQ(consumer.node_id, 1);
  EXPECT_EQ(consumer.time_ms, 500);
  // Node 1 falls silent: the consumer times out (a communication error: sampled at once).
  scheduler_.Advance(600ms);
  ASSERT_TRUE(monitor_.Until([&] {
    const auto& c = monitor_.Node(kNodeId)->status.heartbeat_consumers;
    return !c.empty() && c[0].state == telemetry::HeartbeatConsumerState::kTimedOut;
  }));
}

class UnconfiguredNodeTelemetryTest : public NodeTelemetryWiringTest {
 protected:
  UnconfiguredNodeTelemetryTest() : NodeTelemetryWiringTest(27, canopen::kUnconfiguredNodeId) {}
};

// CiA 305: an unconfigured LSS slave publishes as node 0 (the IDL's key for "none yet"); the
// node-ID a master assigns replaces that instance (disposed) with the new one.
TEST_F(UnconfiguredNodeTelemetryTest, ANodeIdAssignedByLssReplacesNodeZero) {
  ASSERT_TRUE(monitor_.Until([&] { return monitor_.Node(0) != nullptr; }));
  EXPECT_EQ(monitor_.Node(0)->status.device, "quad-controller");
  master_.Send("7E5#0401000000000000");  // switch state global: configuration
  master_.Send("7E5#1107000000000000");  // configure node-ID 7
  master_.Send("7E5#0400000000000000");  // switch state global: waiting → the node takes ID 7
  scheduler_.Advance(1ms);
  ASSERT_TRUE(monitor_.Until([&] {
    return monitor_.Node(7) && monitor_.Node(7)->status.nmt_state == canopen::NmtState::kPreOperational &&
           !monitor_.Node(0)->alive;
  }));
  EXPECT_TRUE(monitor_.Node(0)->disposed);
}

// Shutting down: the wiring goes first and disposes the node's instances; monitors see it leave.
TEST_F(NodeTelemetryWiringTest, DestroyingTheWiringDisposesTheNode) {
  ASSERT_TRUE(monitor_.Until([&] { return monitor_.Node(kNodeId) != nullptr; }));
  wiring_.reset();
  ASSERT_TRUE(monitor_.Until([&] { return !monitor_.Node(kNodeId)->alive; }));
  EXPECT_TRUE(monitor_.Node(kNodeId)->disposed);
  // The hooks and listeners it left behind are no-ops now.
  ASSERT_TRUE(node_->io().SetNumber("IN1.voltage_mV", 3000).ok());
  master_.Send("000#0105");
  scheduler_.Advance(2000ms);
}

// The other order (the node destroyed first) is safe too: the wiring never touches the node again.
TEST_F(NodeTelemetryWiringTest, TheNodeMayGoFirst) {
  ASSERT_TRUE(monitor_.Until([&] { return monitor_.Node(kNodeId) != nullptr; }));
  node_.reset();
  wiring_.reset();
  ASSERT_TRUE(monitor_.Until([&] { return !monitor_.Node(kNodeId)->alive; }));
}

}  // namespace
}  // namespace canfleet::node
