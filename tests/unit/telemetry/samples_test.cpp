// Conversions between the idlc-generated C samples and the C++ values tools work on.
#include <gtest/gtest.h>

#include "telemetry/node_telemetry.hpp"
#include "telemetry/samples.hpp"

namespace canfleet::telemetry {
namespace {

TEST(Bounded, CopyTruncatesAndTerminates) {
  char text[8];
  CopyBounded(text, "can0");
  EXPECT_STREQ(text, "can0");
  CopyBounded(text, "a-very-long-bus-name");
  EXPECT_STREQ(text, "a-very-");  // IDL string<7>: 7 characters and the terminator
}

TEST(Bounded, FromBoundedStopsAtTheArrayEndWithoutTerminator) {
  char text[4] = {'a', 'b', 'c', 'd'};
  EXPECT_EQ(FromBounded(text), "abcd");
}

TEST(Enums, NmtStatesRoundTripAndUnknownIsNullopt) {
  for (auto state :
       {NmtState::kInitialising, NmtState::kStopped, NmtState::kOperational, NmtState::kPreOperational}) {
    EXPECT_EQ(FromDds(ToDds(std::optional<NmtState>(state))), state);
  }
  EXPECT_EQ(ToDds(std::optional<NmtState>()), canfleet_telemetry_NMT_UNKNOWN);
  EXPECT_EQ(FromDds(canfleet_telemetry_NMT_UNKNOWN), std::nullopt);
}

TEST(Enums, ControllerAndConsumerStatesRoundTrip) {
  for (auto state :
       {ControllerState::kErrorActive, ControllerState::kErrorPassive, ControllerState::kBusOff}) {
    EXPECT_EQ(FromDds(ToDds(state)), state);
  }
  for (auto state : {HeartbeatConsumerState::kUnknown, HeartbeatConsumerState::kActive,
                     HeartbeatConsumerState::kTimedOut}) {
    EXPECT_EQ(FromDds(ToDds(state)), state);
  }
  EXPECT_EQ(FromDds(ToDds(FaultAction::kCleared)), FaultAction::kCleared);
}

TEST(FromDds, NodeStatusCopiesEveryField) {
  canfleet_telemetry_HeartbeatConsumer consumers[2] = {
      {3, 250, canfleet_telemetry_HB_CONSUMER_ACTIVE, canfleet_telemetry_NMT_OPERATIONAL},
      {4, 300, canfleet_telemetry_HB_CONSUMER_TIMED_OUT, canfleet_telemetry_NMT_UNKNOWN}};
  canfleet_telemetry_NodeStatus s{};
  CopyBounded(s.bus, "can1");
  s.node_id = 9;
  CopyBounded(s.device, "quad-controller");
  s.nmt_state = canfleet_telemetry_NMT_PRE_OPERATIONAL;
  s.error_register = 0x11;
  s.controller_state = canfleet_telemetry_CONTROLLER_ERROR_PASSIVE;
  s.tec = 130;
  s.rec = 7;
  s.heartbeat_producer_ms = 100;
  s.heartbeat_consumers = {2, 2, consumers, false};
  s.rpdo_count = 5;
  s.tpdo_count = 6;
  s.uptime_ms = 61000;
  s.last_emcy = {true, 0x8130, 0x11, 1234};
  s.publish_period_ms = 1000;
  s.serial = 77;

  const NodeStatusSample out = FromDds(s);
  EXPECT_EQ(out.bus, "can1");
  EXPECT_EQ(out.node_id, 9);
  EXPECT_EQ(out.device, "quad-controller");
  EXPECT_EQ(out.nmt_state, NmtState::kPreOperational);
  EXPECT_EQ(out.error_register, 0x11);
  EXPECT_EQ(out.controller_state, ControllerState::kErrorPassive);
  EXPECT_EQ(out.tec, 130);
  EXPECT_EQ(out.rec, 7);
  ASSERT_EQ(out.heartbeat_consumers.size(), 2u);
  EXPECT_EQ(out.heartbeat_consumers[1].node_id, 4);
  EXPECT_EQ(out.heartbeat_consumers[1].state, HeartbeatConsumerState::kTimedOut);
  EXPECT_EQ(out.heartbeat_consumers[1].last_state, std::nullopt);
  EXPECT_EQ(out.uptime, std::chrono::milliseconds(61000));
  ASSERT_TRUE(out.last_emcy.has_value());
  EXPECT_EQ(out.last_emcy->code, 0x8130);
  EXPECT_EQ(out.last_emcy->bus_time, BusTime(1234));
  EXPECT_EQ(out.publish_period, std::chrono::milliseconds(1000));
  EXPECT_EQ(out.serial, 77u);
}

TEST(FromDds, SequenceLengthIsClampedToItsBound) {
  // A locally built sample claiming more entries than the IDL allows is read up to the bound.
  std::vector<canfleet_telemetry_CobIdRate> rates(40);
  canfleet_telemetry_BusStats s{};
  s.top_cob_ids = {40, 40, rates.data(), false};
  EXPECT_EQ(FromDds(s).top_cob_ids.size(), kMaxTopCobIds);
}

TEST(FromDds, NoValidLastEmcyMeansNullopt) {
  canfleet_telemetry_NodeStatus s{};
  EXPECT_FALSE(FromDds(s).last_emcy.has_value());
}

TEST(StatusChanged, CountersAloneAreNotAChange) {
  NodeStatusSnapshot a;
  NodeStatusSnapshot b = a;
  b.rpdo_count = 100;
  b.tpdo_count = 100;
  EXPECT_FALSE(StatusChanged(a, b));
  b.tec = 1;
  EXPECT_TRUE(StatusChanged(a, b));
}

TEST(StatusChanged, OnlyTheUsedConsumerEntriesCount) {
  NodeStatusSnapshot a;
  a.heartbeat_consumer_count = 1;
  NodeStatusSnapshot b = a;
  b.heartbeat_consumers[5].state = HeartbeatConsumerState::kTimedOut;  // beyond the count: ignored
  EXPECT_FALSE(StatusChanged(a, b));
  b.heartbeat_consumers[0].state = HeartbeatConsumerState::kTimedOut;
  EXPECT_TRUE(StatusChanged(a, b));
}

}  // namespace
}  // namespace canfleet::telemetry
