// What the master sees of each node on the wire (orchestrator/fleet/node_tracker): CiA 301
// §7.2.8.3.2 boot-up and heartbeat (700h + id, one state byte), §7.2.7 EMCY (80h + id, 8 bytes).
#include "orchestrator/fleet/node_tracker.hpp"

#include <gtest/gtest.h>

#include "tests/support/bus_probe.hpp"

namespace canfleet::fleet {
namespace {

TEST(NodeTracker, BootUpHeartbeatAndEmcyAreRecorded) {
  NodeTracker tracker;
  std::vector<int> boots;
  tracker.OnBootUp([&](const std::string&, std::uint8_t id) { boots.push_back(id); });
  const TimePoint t0{std::chrono::seconds(1)};
  tracker.Observe("can0", test::Frame("705#00"), t0);
  ASSERT_NE(tracker.Find("can0", 5), nullptr);
  EXPECT_TRUE(tracker.Find("can0", 5)->booted);
  EXPECT_STREQ(NmtStateName(tracker.Find("can0", 5)->nmt_state), "initialising");
  tracker.Observe("can0", test::Frame("705#05"), t0 + std::chrono::milliseconds(100));
  EXPECT_STREQ(NmtStateName(tracker.Find("can0", 5)->nmt_state), "operational");
  EXPECT_EQ(*tracker.Find("can0", 5)->last_heartbeat, t0 + std::chrono::milliseconds(100));
  tracker.Observe("can0", test::Frame("085#3081110506000000"), t0);
  const auto& emcy = *tracker.Find("can0", 5)->last_emcy;
  EXPECT_EQ(emcy.code, 0x8130);
  EXPECT_EQ(emcy.error_register, 0x11);
  EXPECT_EQ(emcy.manufacturer[0], 0x05);
  EXPECT_EQ(boots, std::vector<int>{5});
  EXPECT_EQ(tracker.Find("can1", 5), nullptr);  // buses are separate
}

TEST(NodeTracker, AStateNotHeardForThreeHeartbeatPeriodsIsStale) {
  // Issue 32: status never shows a state it has not seen recently (a babbling idiot's flood, a
  // partition). On simulated time: heartbeats every 500 ms, then none.
  using std::chrono::milliseconds;
  NodeTracker tracker;
  const TimePoint t0{std::chrono::seconds(1)};
  tracker.Observe("can0", test::Frame("705#00"), t0);
  EXPECT_FALSE(tracker.Find("can0", 5)->Stale(t0 + std::chrono::hours(1))) << "no period seen: never stale";
  tracker.Observe("can0", test::Frame("705#7F"), t0 + milliseconds(500));
  tracker.Observe("can0", test::Frame("705#05"), t0 + milliseconds(1000));
  const auto& live = *tracker.Find("can0", 5);
  ASSERT_TRUE(live.heartbeat_period.has_value());
  EXPECT_EQ(*live.heartbeat_period, milliseconds(500));
  EXPECT_FALSE(live.Stale(t0 + milliseconds(2500)));
  EXPECT_TRUE(live.Stale(t0 + milliseconds(2501)));
  tracker.Observe("can0", test::Frame("705#05"), t0 + milliseconds(4000));  // heard again
  EXPECT_FALSE(tracker.Find("can0", 5)->Stale(t0 + milliseconds(4001)));
  EXPECT_EQ(*tracker.Find("can0", 5)->heartbeat_period, milliseconds(500)) << "the gap does not stretch it";
  EXPECT_TRUE(tracker.Find("can0", 5)->Stale(t0 + milliseconds(5501)));
  tracker.Observe("can0", test::Frame("705#00"), t0 + milliseconds(4100));  // a boot-up starts over
  EXPECT_FALSE(tracker.Find("can0", 5)->heartbeat_period.has_value());
}

TEST(NodeTracker, OtherFramesAndBadLengthsAreIgnored) {
  NodeTracker tracker;
  tracker.Observe("can0", test::Frame("705#0500"), TimePoint{});  // DLC 2: not a heartbeat
  tracker.Observe("can0", test::Frame("085#3081"), TimePoint{});  // DLC 2: not an EMCY
  tracker.Observe("can0", test::Frame("080#00"), TimePoint{});    // SYNC
  tracker.Observe("can0", test::Frame("700#00"), TimePoint{});    // node-ID 0 does not exist
  EXPECT_EQ(tracker.Find("can0", 5), nullptr);
  EXPECT_EQ(tracker.Find("can0", 0), nullptr);
}

TEST(NodeTracker, ForgetDropsWhatWasSeen) {
  NodeTracker tracker;
  tracker.Observe("can0", test::Frame("705#7F"), TimePoint{});
  EXPECT_STREQ(NmtStateName(tracker.Find("can0", 5)->nmt_state), "pre-operational");
  tracker.Forget("can0", 5);
  EXPECT_EQ(tracker.Find("can0", 5), nullptr);
}

}  // namespace
}  // namespace canfleet::fleet
