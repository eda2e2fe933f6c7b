// Issue 6, fault 4: frame faults, partition, babbling idiot and error-passive, each with its
// observable effect, on a real fleet of two Quads (AX020506) through the real CLI.
#include <gtest/gtest.h>

#include "tests/system/fleet/fleet_harness.hpp"

namespace canfleet::system_test {
namespace {

constexpr auto kLong = std::chrono::seconds(30);

// quad-6 consumes quad-5's heartbeat (§4.1: a loss is EMCY 8130h), both produce every 200 ms.
constexpr const char* kTopology = R"(
name: "fleet-test"
bus { name: "can0" bitrate: 250000 }
node { name: "quad-5" device: "quad-controller" node_id: 5 bus: "can0"
       heartbeat { producer_ms: 200 } }
node { name: "quad-6" device: "quad-controller" node_id: 6 bus: "can0"
       heartbeat { producer_ms: 200 consumer { node: "quad-5" timeout_ms: 1000 } } }
)";

class FleetFrameFaultsTest : public ::testing::Test {
 protected:
  void SetUp() override { ASSERT_TRUE(fleet.WaitReady()) << fleet.Log(); }

  const control::NodeStatus Node(const std::string& name) const {
    const auto status = fleet.Status();
    const auto* n = fleet.Node(status, name);
    return n ? *n : control::NodeStatus{};
  }
  std::uint64_t Hits(std::uint32_t id) const {
    control::FaultList list;
    ParseJson(fleet.Cli({"fault", "list", "--all", "--json"}).out, list);
    for (const auto& f : list.faults())
      if (f.fault_id() == id) return f.hits();
    return 0;
  }
  std::uint32_t Inject(std::vector<std::string> args) const {
    args.insert(args.begin(), {"fault", "inject"});
    args.push_back("--json");
    const auto result = fleet.Cli(args);
    EXPECT_EQ(result.exit_code, 0) << result.err;
    control::FaultInjected injected;
    ParseJson(result.out, injected);
    return injected.fault_id();
  }

  FleetUnderTest fleet{kTopology};
};

TEST_F(FleetFrameFaultsTest, DropWithACountExpiresAfterThatManyFrames) {
  const auto id = Inject({"drop", "--node", "quad-5", "--cob-id", "0x705", "--count", "3"});
  EXPECT_TRUE(WaitUntil([&] { return Hits(id) == 3; }, kLong));
  // The rule is used up: heartbeats reach the master again.
  EXPECT_TRUE(WaitUntil([&] { return Node("quad-5").heartbeat_age_s() < 0.5; }, kLong));
}

TEST_F(FleetFrameFaultsTest, DelayPostponesFramesWithoutLosingThem) {
  const auto id =
      Inject({"delay", "--node", "quad-5", "--cob-id", "0x705", "--delay", "50ms", "--jitter", "10ms"});
  EXPECT_TRUE(WaitUntil([&] { return Hits(id) >= 5; }, kLong));
  // Delayed, not lost: quad-6's consumer (1000 ms) raises nothing.
  EXPECT_NE(Node("quad-6").last_emcy().code(), 0x8130u);
}

TEST_F(FleetFrameFaultsTest, CorruptRaisesTheSendersTransmitErrorCounter) {
  Inject({"corrupt", "--node", "quad-5", "--count", "12"});
  // 12 error frames: TEC +8 each, -1 per success; it passes 8 whatever the interleaving.
  EXPECT_TRUE(WaitUntil(
      [&] {
        const auto status = fleet.Status();
        return fleet.Node(status, "quad-5")->tec() >= 8 && status.buses(0).error_frames() >= 12;
      },
      kLong))
      << fleet.Log();
}

TEST_F(FleetFrameFaultsTest, DuplicateDeliversFramesTwice) {
  const auto id = Inject({"duplicate", "--node", "quad-5", "--cob-id", "0x705", "--count", "4"});
  EXPECT_TRUE(WaitUntil([&] { return Hits(id) == 4; }, kLong));
}

TEST_F(FleetFrameFaultsTest, PartitionSeparatesGroupsUntilHealed) {
  // CiA 301 §7.2.8.3.2: a consumer starts watching at the first heartbeat it receives. Let a few
  // of quad-5's (every 200 ms) reach quad-6 after it was configured before partitioning.
  const double ready_at = fleet.Status().uptime_s();
  ASSERT_TRUE(WaitUntil([&] { return fleet.Status().uptime_s() > ready_at + 1.0; }, kLong));
  Inject({"partition", "--group", "quad-5", "--group", "quad-6", "--label", "split"});
  EXPECT_TRUE(WaitUntil([&] { return Node("quad-6").last_emcy().code() == 0x8130; }, kLong)) << fleet.Log();
  // The master is in no group: it still hears both.
  EXPECT_LT(Node("quad-5").heartbeat_age_s(), 1.0);
  ASSERT_EQ(fleet.Cli({"fault", "clear", "--label", "split"}).exit_code, 0);
  EXPECT_TRUE(WaitUntil([&] { return Node("quad-6").last_emcy().code() == 0x0000; }, kLong));
}

TEST_F(FleetFrameFaultsTest, BabblingIdiotFillsTheBusAndStarvesLowerPriorities) {
  Inject({"babbling-idiot", "--node", "quad-5", "--cob-id", "0x001"});
  EXPECT_TRUE(WaitUntil([&] { return fleet.Status().buses(0).load_percent() > 90; }, kLong)) << fleet.Log();
  // quad-6's heartbeat (706h) loses every arbitration against 001h.
  EXPECT_TRUE(WaitUntil([&] { return Node("quad-6").heartbeat_age_s() > 2.0; }, kLong));
  ASSERT_EQ(fleet.Cli({"fault", "clear", "--all"}).exit_code, 0);
  EXPECT_TRUE(WaitUntil([&] { return Node("quad-6").heartbeat_age_s() < 1.0; }, kLong));
}

TEST_F(FleetFrameFaultsTest, ErrorPassiveIsHeldUntilCleared) {
  Inject({"error-passive", "--node", "quad-5"});
  EXPECT_TRUE(WaitUntil(
      [&] {
        const auto n = Node("quad-5");
        return n.controller() == "error-passive" && n.tec() >= 128;
      },
      kLong))
      << fleet.Log();
  // CiA 301: EMCY 8120h "CAN in error passive mode" (an error-passive node still transmits).
  EXPECT_TRUE(WaitUntil([&] { return Node("quad-5").last_emcy().code() == 0x8120; }, kLong));
  ASSERT_EQ(fleet.Cli({"fault", "clear", "--all"}).exit_code, 0);
  EXPECT_TRUE(WaitUntil([&] { return Node("quad-5").controller() == "error-active"; }, kLong));
}

}  // namespace
}  // namespace canfleet::system_test
