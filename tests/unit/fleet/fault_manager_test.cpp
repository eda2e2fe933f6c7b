// FaultManager (orchestrator/fleet/fault_manager): each fault of the control API becomes the
// right broker rule or controller fault, lives for its duration, and is cleared cleanly. The
// broker is real (in process, simulated time); its ports are recording sinks named as nodes.
#include "orchestrator/fleet/fault_manager.hpp"

#include <gtest/gtest.h>

#include <asio/io_context.hpp>

#include "clock/scheduler.hpp"
#include "tests/support/bus_probe.hpp"

namespace canfleet::fleet {
namespace {

using namespace std::chrono_literals;

class NullSink final : public broker::PortSink {
 public:
  void Deliver(std::span<const broker::TimedFrame> frames) override { received += frames.size(); }
  void ControllerChanged(const ControllerEvent& event) override { state = event.state; }
  std::size_t received = 0;
  ControllerState state = ControllerState::kErrorActive;
};

class FaultManagerTest : public ::testing::Test {
 protected:
  FaultManagerTest() {
    broker.AddBus({.name = "can0", .bitrate = 250'000});
    for (const auto& [name, id] : {std::pair{"quad-5", 5}, {"quad-6", 6}, {"quad-7", 7}}) {
      FleetNode node;
      node.spec.set_name(name);
      node.buses = {"can0"};
      node.node_ids = {static_cast<std::uint8_t>(id)};
      nodes.push_back(node);
      ports[name] = broker.Attach("can0", name, sinks[name]);
    }
    faults = std::make_unique<FaultManager>(FaultManager::Context{
        .broker = broker,
        .scheduler = scheduler,
        .supervisor = supervisor,
        .find_node = [this](const std::string& name) -> const FleetNode* {
          for (const auto& n : nodes)
            if (n.name() == name) return &n;
          return nullptr;
        },
        .unknown_node = nullptr,
        .origin = scheduler.Now(),
        .on_event = [this](const control::FaultStatus& s,
                           bool started) { events.push_back((started ? "+" : "-") + s.state()); },
    });
  }

  control::FaultSpec Spec(control::FaultKind kind, const std::string& node = "") {
    control::FaultSpec spec;
    spec.set_kind(kind);
    spec.set_node(node);
    return spec;
  }

  SimulatedScheduler scheduler;
  broker::Broker broker{scheduler};
  asio::io_context io;
  Supervisor supervisor{io, scheduler, {}};
  std::vector<FleetNode> nodes;
  std::map<std::string, NullSink> sinks;
  std::map<std::string, broker::PortId> ports;
  std::unique_ptr<FaultManager> faults;
  std::vector<std::string> events;
};

TEST_F(FaultManagerTest, HeartbeatLossDropsTheNodesHeartbeatForTheChosenReceivers) {
  auto spec = Spec(control::HEARTBEAT_LOSS, "quad-5");
  spec.add_receivers("quad-6");
  const auto injected = faults->Inject(spec);
  const auto rules = broker.Faults("can0").List();
  ASSERT_EQ(rules.size(), 1u);
  EXPECT_EQ(rules[0].rule.source, ports["quad-5"]);
  EXPECT_EQ(rules[0].rule.id, 0x705u);
  EXPECT_EQ(rules[0].rule.mask, 0x7FFu);
  EXPECT_EQ(rules[0].rule.receivers, std::vector<broker::PortId>{ports["quad-6"]});
  EXPECT_EQ(rules[0].rule.action, broker::RuleAction::kDrop);

  control::FaultClear clear;
  clear.set_fault_id(injected.fault_id());
  EXPECT_EQ(faults->Clear(clear), 1u);
  EXPECT_TRUE(broker.Faults("can0").List().empty());
  EXPECT_EQ(events, (std::vector<std::string>{"+active", "-cleared"}));
  const auto log = faults->List(true);
  ASSERT_EQ(log.size(), 1u);
  EXPECT_EQ(log[0].state(), "cleared");
}

TEST_F(FaultManagerTest, RpdoTimeoutDropsTheCobIdForTheReceivingNodeOnly) {
  auto spec = Spec(control::RPDO_TIMEOUT, "quad-6");
  EXPECT_THROW(faults->Inject(spec), FaultError);  // needs the COB-ID
  spec.set_cob_id(0x185);
  faults->Inject(spec);
  const auto rules = broker.Faults("can0").List();
  ASSERT_EQ(rules.size(), 1u);
  EXPECT_FALSE(rules[0].rule.source.has_value());
  EXPECT_EQ(rules[0].rule.id, 0x185u);
  EXPECT_EQ(rules[0].rule.receivers, std::vector<broker::PortId>{ports["quad-6"]});
}

TEST_F(FaultManagerTest, DurationExpiresTheFault) {
  auto spec = Spec(control::DROP, "quad-5");
  spec.set_duration_ms(500);
  faults->Inject(spec);
  scheduler.Advance(499ms);
  EXPECT_EQ(faults->List(false).size(), 1u);
  scheduler.Advance(1ms);
  EXPECT_TRUE(faults->List(false).empty());
  EXPECT_EQ(faults->List(true).at(0).state(), "expired");
  EXPECT_TRUE(broker.Faults("can0").List().empty());
}

TEST_F(FaultManagerTest, PartitionDropsBetweenGroupsOnlyAndHeals) {
  auto spec = Spec(control::PARTITION);
  spec.add_groups()->add_nodes("quad-5");
  auto* second = spec.add_groups();
  second->add_nodes("quad-6");
  second->add_nodes("quad-7");
  faults->Inject(spec);
  const auto rules = broker.Faults("can0").List();
  ASSERT_EQ(rules.size(), 3u);  // one per member, towards the other group
  EXPECT_EQ(rules[0].rule.receivers, (std::vector<broker::PortId>{ports["quad-6"], ports["quad-7"]}));
  EXPECT_EQ(rules[1].rule.receivers, std::vector<broker::PortId>{ports["quad-5"]});
  EXPECT_EQ(faults->Clear({}), 1u);
  EXPECT_TRUE(broker.Faults("can0").List().empty());
}

TEST_F(FaultManagerTest, BadRequestsAreRefusedWithoutSideEffects) {
  EXPECT_THROW(faults->Inject(Spec(control::HEARTBEAT_LOSS, "nobody")), FaultError);
  EXPECT_THROW(faults->Inject(Spec(control::HEARTBEAT_LOSS)), FaultError);
  EXPECT_THROW(faults->Inject(Spec(control::FAULT_KIND_UNSPECIFIED, "quad-5")), FaultError);
  auto partition = Spec(control::PARTITION);
  partition.add_groups()->add_nodes("quad-5");
  partition.add_groups()->add_nodes("ghost");
  EXPECT_THROW(faults->Inject(partition), FaultError);
  EXPECT_THROW(faults->Inject(Spec(control::KILL, "quad-5")), FaultError);  // not supervised here
  EXPECT_TRUE(broker.Faults("can0").List().empty());
  EXPECT_TRUE(faults->List(true).empty());
  control::FaultClear clear;
  clear.set_fault_id(42);
  EXPECT_THROW(faults->Clear(clear), FaultError);
}

TEST_F(FaultManagerTest, LabelsAreUniqueAmongActiveFaults) {
  auto spec = Spec(control::DROP, "quad-5");
  spec.set_label("x");
  faults->Inject(spec);
  EXPECT_THROW(faults->Inject(spec), FaultError);
  control::FaultClear clear;
  clear.set_label("x");
  EXPECT_EQ(faults->Clear(clear), 1u);
  faults->Inject(spec);  // free again
}

TEST_F(FaultManagerTest, BusOffWithManualRecoveryHoldsUntilCleared) {
  auto spec = Spec(control::BUS_OFF, "quad-5");
  spec.set_manual_recovery(true);
  faults->Inject(spec);
  scheduler.Advance(100ms);  // far beyond 1408 bit times at 250 kbit/s
  EXPECT_EQ(broker.Port(ports["quad-5"]).controller.state, ControllerState::kBusOff);
  faults->Clear({});
  EXPECT_EQ(broker.Port(ports["quad-5"]).controller.state, ControllerState::kErrorActive);
}

// A bus-off held for a duration is a cause that persists: the node stays bus-off (TEC 256) for
// the whole duration while its recovery attempts (every 1408 bit times = 5.632 ms at 250 kbit/s,
// ISO 11898-1:2015 §12.1.4.2) fail and are counted as the fault's hits; then the next attempt
// succeeds.
TEST_F(FaultManagerTest, BusOffHeldForADurationFailsEveryRecoveryAttemptUntilItEnds) {
  auto spec = Spec(control::BUS_OFF, "quad-5");
  spec.set_duration_ms(100);
  const auto injected = faults->Inject(spec);
  EXPECT_EQ(injected.summary(),
            "bus-off of quad-5 on can0, held for 100ms (every recovery attempt fails until then)");
  for (int step = 0; step < 9; ++step) {
    scheduler.Advance(11ms);
    const auto port = broker.Port(ports["quad-5"]);
    EXPECT_EQ(port.controller.state, ControllerState::kBusOff) << step;
    EXPECT_EQ(port.controller.tec, 256) << step;
  }
  const auto active = faults->List(false);
  ASSERT_EQ(active.size(), 1u);
  EXPECT_EQ(active[0].state(), "active");
  EXPECT_EQ(active[0].hits(), 17u);  // 99 ms / 5.632 ms
  scheduler.Advance(1ms);            // 100 ms: the cause ends
  EXPECT_EQ(faults->List(true).at(0).state(), "expired");
  EXPECT_EQ(faults->List(true).at(0).hits(), 17u);
  EXPECT_EQ(broker.Port(ports["quad-5"]).controller.state, ControllerState::kBusOff);
  scheduler.Advance(std::chrono::microseconds(5632));  // the next attempt, 18 × 5.632 ms after the bus-off
  EXPECT_EQ(sinks["quad-5"].state, ControllerState::kErrorActive);
  EXPECT_EQ(events, (std::vector<std::string>{"+active", "-expired"}));
}

// Options a kind does not take, and forms of a kind that exclude each other, are refused with
// the CLI's names (the control API's errors are printed by `canfleet`), and nothing is applied.
TEST_F(FaultManagerTest, OptionsThatDoNotApplyAreRefusedNotIgnored) {
  auto message = [&](const control::FaultSpec& spec) -> std::string {
    try {
      faults->Inject(spec);
    } catch (const FaultError& e) {
      return e.what();
    }
    return "(accepted)";
  };
  auto bus_off = Spec(control::BUS_OFF, "quad-5");
  bus_off.set_cob_id(0x185);
  EXPECT_EQ(
      message(bus_off),
      "--cob-id does not apply to bus-off (it takes --node, --bus, --duration, --manual-recovery, --label)");
  bus_off.clear_cob_id();
  bus_off.set_manual_recovery(true);
  bus_off.set_duration_ms(2000);
  EXPECT_EQ(message(bus_off), "--duration and --manual-recovery are two forms of bus-off: give one");
  auto corrupt = Spec(control::CORRUPT, "quad-5");
  corrupt.add_receivers("quad-6");
  EXPECT_EQ(message(corrupt).find("--receiver does not apply to corrupt (it takes"), 0u);
  auto drop = Spec(control::DROP, "quad-5");
  drop.set_delay_ms(10);
  EXPECT_EQ(message(drop).find("--delay does not apply to drop (it takes"), 0u);
  auto restart = Spec(control::RESTART, "quad-5");
  restart.set_duration_ms(1000);
  EXPECT_EQ(message(restart), "--duration does not apply to restart (it takes --node, --label)");
  EXPECT_EQ(message(Spec(control::RPDO_TIMEOUT, "quad-6")),
            "required: rpdo-timeout needs the COB-ID of the RPDO that stops reaching the node (--cob-id)");
  EXPECT_TRUE(broker.Faults("can0").List().empty());
  EXPECT_TRUE(faults->List(true).empty());
  EXPECT_EQ(broker.Port(ports["quad-5"]).controller.state, ControllerState::kErrorActive);
}

// What the summary of heartbeat-loss has always said is now done: probability, seed and count
// reach the broker's drop rule.
TEST_F(FaultManagerTest, HeartbeatLossTakesProbabilitySeedAndCount) {
  auto spec = Spec(control::HEARTBEAT_LOSS, "quad-5");
  spec.set_probability(0.5);
  spec.set_seed(7);
  spec.set_count(3);
  faults->Inject(spec);
  const auto rules = broker.Faults("can0").List();
  ASSERT_EQ(rules.size(), 1u);
  EXPECT_EQ(rules[0].rule.probability, 0.5);
  EXPECT_EQ(rules[0].rule.seed, 7u);
  EXPECT_EQ(rules[0].rule.count, std::optional<std::uint64_t>(3));
}

TEST_F(FaultManagerTest, ErrorPassiveIsHeldAndReleased) {
  faults->Inject(Spec(control::ERROR_PASSIVE, "quad-5"));
  scheduler.Advance(10ms);
  EXPECT_EQ(broker.Port(ports["quad-5"]).controller.state, ControllerState::kErrorPassive);
  faults->Clear({});
  scheduler.Advance(10ms);
  EXPECT_EQ(broker.Port(ports["quad-5"]).controller.state, ControllerState::kErrorActive);
}

TEST_F(FaultManagerTest, BabblingIdiotKeepsTheNodesQueueFull) {
  auto spec = Spec(control::BABBLING_IDIOT, "quad-5");
  faults->Inject(spec);
  scheduler.Advance(100ms);
  const auto stats = broker.Stats("can0");
  EXPECT_GT(stats.load_percent, 90.0);
  EXPECT_GT(sinks["quad-6"].received, 100u);
  faults->Clear({});
  const auto hits = faults->List(true).at(0).hits();
  EXPECT_GT(hits, 100u);
}

// A participant (a client attached by name that is no node of the topology, e.g. a test's python-can
// bus, python/README.md): controller and frame faults act on its port as on a node's; what needs a
// CANopen node-ID or a process of the fleet is refused with a reason.
TEST_F(FaultManagerTest, AParticipantAttachedByNameTakesBusAndFrameFaultsButNotNodeFaults) {
  NullSink participant_sink;
  const auto participant = broker.Attach("can0", "pytest-bus", participant_sink);
  faults->Inject(Spec(control::BUS_OFF, "pytest-bus"));
  scheduler.Advance(1ms);
  EXPECT_EQ(broker.Port(participant).controller.state, ControllerState::kBusOff);
  EXPECT_EQ(participant_sink.state, ControllerState::kBusOff);

  auto drop = Spec(control::DROP, "pytest-bus");
  drop.set_cob_id(0x601);
  faults->Inject(drop);
  const auto rules = broker.Faults("can0").List();
  ASSERT_EQ(rules.size(), 1u);
  EXPECT_EQ(rules[0].rule.source, std::optional<broker::PortId>(participant));

  try {
    faults->Inject(Spec(control::HEARTBEAT_LOSS, "pytest-bus"));
    ADD_FAILURE() << "heartbeat-loss of a participant was accepted";
  } catch (const FaultError& e) {
    EXPECT_NE(std::string(e.what()).find("participant, not a CANopen node"), std::string::npos) << e.what();
  }
  EXPECT_THROW(faults->Inject(Spec(control::KILL, "pytest-bus")), FaultError);
  try {
    faults->Inject(Spec(control::BUS_OFF, "ghost"));
    ADD_FAILURE() << "a fault on a name nobody has was accepted";
  } catch (const FaultError& e) {
    EXPECT_NE(std::string(e.what()).find("no node called 'ghost'"), std::string::npos) << e.what();
  }
  // Gone from the bus, it is nobody.
  broker.Detach(participant);
  EXPECT_THROW(faults->Inject(Spec(control::ERROR_PASSIVE, "pytest-bus")), FaultError);
}

}  // namespace
}  // namespace canfleet::fleet
