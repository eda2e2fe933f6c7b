// The Broker's edges: buses and ports, refused input, TX queues, detaching under traffic.
#include "orchestrator/broker/broker.hpp"

#include <gtest/gtest.h>

#include "tests/unit/broker/broker_test_support.hpp"

namespace canfleet::broker {
namespace {

using namespace test;

TEST(BrokerBuses, BusesAreNamedAndValidated) {
  SimulatedScheduler s;
  Broker broker(s);
  broker.AddBus({.name = "can0"});
  broker.AddBus({.name = "can1", .bitrate = 1'000'000});
  broker.AddBus({.name = "slow", .bitrate = 10'000});
  EXPECT_THROW(broker.AddBus({.name = "can0"}), std::invalid_argument);
  EXPECT_THROW(broker.AddBus({.name = "x", .bitrate = 9'999}), std::invalid_argument);
  EXPECT_THROW(broker.AddBus({.name = "y", .bitrate = 1'000'001}), std::invalid_argument);
  EXPECT_THROW(broker.AddBus({.name = ""}), std::invalid_argument);
  EXPECT_THROW(broker.AddBus({.name = "z", .tx_queue_capacity = 0}), std::invalid_argument);
  EXPECT_EQ(broker.Buses(), (std::vector<std::string>{"can0", "can1", "slow"}));
  RecordingSink sink;
  EXPECT_THROW(broker.Attach("can9", "n", sink), std::invalid_argument);
  EXPECT_THROW(broker.Faults("can9"), std::invalid_argument);
  EXPECT_THROW(broker.Stats("can9"), std::invalid_argument);
  EXPECT_THROW(broker.Port(42), std::invalid_argument);
}

// Buses are separate wires: frames do not cross, each has its own time line.
TEST(BrokerBuses, BusesAreIndependent) {
  SimulatedScheduler s;
  Broker broker(s);
  broker.AddBus({.name = "can0", .bitrate = 125'000});
  broker.AddBus({.name = "can1", .bitrate = 1'000'000});
  RecordingSink a0, b0, a1, b1;
  const PortId pa0 = broker.Attach("can0", "a", a0);
  broker.Attach("can0", "b", b0);
  const PortId pa1 = broker.Attach("can1", "a", a1);
  broker.Attach("can1", "b", b1);
  broker.Submit(pa0, Frame("000#"));
  broker.Submit(pa1, Frame("000#"));
  s.Advance(1s);
  EXPECT_EQ(b0.Received(), (std::vector<std::string>{"000#@424000"}));  // 53 bits × 8 µs
  EXPECT_EQ(b1.Received(), (std::vector<std::string>{"000#@53000"}));   // 53 bits × 1 µs
  const auto ports = broker.Ports("can1");
  ASSERT_EQ(ports.size(), 2u);
  EXPECT_EQ(ports[0].id, pa1);
  EXPECT_EQ(ports[0].name, "a");
  EXPECT_EQ(ports[0].bus, "can1");
}

// Like a CAN driver's queue: frames beyond the capacity are dropped and counted.
TEST(BrokerQueues, OverflowIsDroppedAndCounted) {
  SimulatedScheduler s;
  Broker broker(s);
  broker.AddBus({.name = "can0", .tx_queue_capacity = 4});
  RecordingSink a, b;
  const PortId pa = broker.Attach("can0", "a", a);
  broker.Attach("can0", "b", b);
  std::vector<CanFrame> frames;
  for (int i = 0; i < 10; ++i)
    frames.push_back(CanFrame::Data(0x181, {static_cast<std::uint8_t>(i)}));
  EXPECT_EQ(broker.Submit(pa, frames), 4u);
  EXPECT_EQ(broker.Port(pa).queue_drops, 6u);
  EXPECT_EQ(broker.Port(pa).queued, 4u);
  EXPECT_EQ(broker.Stats("can0").queue_drops, 6u);
  s.Advance(1s);
  EXPECT_EQ(b.Ids(), (std::vector<std::string>{"181#00", "181#01", "181#02", "181#03"}));
  EXPECT_EQ(broker.Submit(pa, frames), 4u);  // room again
}

TEST(BrokerQueues, InvalidFramesAreDroppedAndCounted) {
  SimulatedScheduler s;
  Broker broker(s);
  broker.AddBus({.name = "can0"});
  RecordingSink a, b;
  const PortId pa = broker.Attach("can0", "a", a);
  broker.Attach("can0", "b", b);
  CanFrame long_dlc = Frame("123#"), wide_id = Frame("123#"), error = Frame("123#");
  long_dlc.dlc = 9;
  wide_id.id = 0x800;  // 11-bit frame with a 12-bit id
  error.flags = CanFrame::kError;
  const CanFrame frames[] = {long_dlc, wide_id, error, Frame("124#01")};
  EXPECT_EQ(broker.Submit(pa, frames), 1u);
  EXPECT_EQ(broker.Port(pa).invalid_drops, 3u);
  s.Advance(1s);
  EXPECT_EQ(b.Ids(), (std::vector<std::string>{"124#01"}));
}

// Bytes beyond the DLC are not part of a frame: they reach nobody.
TEST(BrokerQueues, BytesBeyondTheDlcAreCleared) {
  SimulatedScheduler s;
  Broker broker(s);
  broker.AddBus({.name = "can0"});
  RecordingSink a, b;
  const PortId pa = broker.Attach("can0", "a", a);
  broker.Attach("can0", "b", b);
  CanFrame f = Frame("123#0102");
  f.data[5] = 0xEE;
  broker.Submit(pa, f);
  s.Advance(1s);
  ASSERT_EQ(b.frames.size(), 1u);
  EXPECT_EQ(b.frames[0].frame.data[5], 0);
}

class DetachUnderTraffic : public ::testing::Test {
 protected:
  SimulatedScheduler s;
  Broker broker{s};
  bool bus_added = (broker.AddBus({.name = "can0"}), true);
  RecordingSink a{&s}, b{&s}, c{&s};
  PortId pa = broker.Attach("can0", "a", a);
  PortId pb = broker.Attach("can0", "b", b);
  PortId pc = broker.Attach("can0", "c", c);
};

// A port that detaches from inside its own Deliver gets nothing more; the others carry on.
TEST_F(DetachUnderTraffic, APortDetachingFromInsideItsSink) {
  c.on_deliver = [&](std::span<const TimedFrame>) { broker.Detach(pc); };
  for (int i = 0; i < 5; ++i)
    broker.Submit(pa, CanFrame::Data(0x181, {static_cast<std::uint8_t>(i)}));
  s.Advance(1s);
  EXPECT_EQ(c.Ids(), (std::vector<std::string>{"181#00"}));
  EXPECT_EQ(b.frames.size(), 5u);
  EXPECT_THROW(broker.Port(pc), std::invalid_argument);
  EXPECT_EQ(broker.Submit(pc, Frame("123#")), 0u);
  EXPECT_FALSE(broker.Detach(pc));
  EXPECT_EQ(broker.Ports("can0").size(), 2u);
}

// A sender detached while its frame is on the wire: the frame completes for the receivers, the
// sender's queue is discarded and it gets no confirmation.
TEST_F(DetachUnderTraffic, ASenderDetachedWhileItsFrameIsOnTheWire) {
  const CanFrame frames[] = {Frame("181#01"), Frame("181#02")};
  broker.Submit(pa, frames);
  broker.Submit(pb, Frame("182#01"));
  s.Advance(20us);
  EXPECT_TRUE(broker.Detach(pa));
  s.Advance(1s);
  EXPECT_EQ(c.Ids(), (std::vector<std::string>{"181#01", "182#01"}));
  EXPECT_TRUE(a.confirmed.empty());
  EXPECT_TRUE(a.frames.empty());
  EXPECT_EQ(broker.Stats("can0").ports, 2u);
}

// Detaching the only other port while a frame is queued: the remaining port is alone and gets
// ACK errors, like a node whose peer was unplugged.
TEST_F(DetachUnderTraffic, APortLeftAloneGetsAckErrors) {
  broker.Detach(pc);
  broker.Detach(pb);
  broker.Submit(pa, Frame("181#01"));
  s.Advance(10ms);
  EXPECT_GT(broker.Port(pa).tx_errors, 0u);
  EXPECT_EQ(a.States(), (std::vector<ControllerState>{ControllerState::kErrorPassive}));
}

// Ports attached while a frame is on the wire do not receive it (they missed its start).
TEST_F(DetachUnderTraffic, APortAttachedDuringAFrameMissesIt) {
  RecordingSink late;
  broker.Submit(pa, Frame("181#01"));
  s.Advance(20us);
  broker.Attach("can0", "late", late);
  broker.Submit(pa, Frame("181#02"));
  s.Advance(1s);
  EXPECT_EQ(late.Ids(), (std::vector<std::string>{"181#02"}));
}

}  // namespace
}  // namespace canfleet::broker
