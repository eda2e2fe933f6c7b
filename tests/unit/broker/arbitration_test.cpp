// Bus arbitration by identifier, ISO 11898-1:2015 §6.3 (bus access method) and the arbitration
// field of §10.4: bit by bit, a dominant 0 overwrites a recessive 1 and a node that sends
// recessive but reads dominant withdraws; the frame with the lowest arbitration field wins.
#include "bus/physics/wire_model.hpp"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "orchestrator/broker/broker.hpp"
#include "tests/unit/broker/broker_test_support.hpp"

namespace canfleet::broker {
namespace {

using namespace test;

/// Reference model: the arbitration bits as they go on the wire, one per bit time.
std::vector<int> WireBits(const CanFrame& f) {
  std::vector<int> bits;
  auto push = [&](std::uint32_t value, int count) {
    for (int i = count - 1; i >= 0; --i)
      bits.push_back(static_cast<int>((value >> i) & 1U));
  };
  if (f.extended()) {
    push(f.id >> 18, 11);
    push(1, 1);  // SRR
    push(1, 1);  // IDE
    push(f.id & 0x3FFFF, 18);
    push(f.remote() ? 1 : 0, 1);  // RTR
  } else {
    push(f.id, 11);
    push(f.remote() ? 1 : 0, 1);  // RTR
    push(0, 1);                   // IDE
  }
  return bits;
}

/// Wired-AND arbitration between two transmitters: -1 if a wins, 1 if b wins, 0 if neither drops out.
int WireArbitration(const CanFrame& a, const CanFrame& b) {
  auto x = WireBits(a), y = WireBits(b);
  for (std::size_t i = 0; i < std::min(x.size(), y.size()); ++i) {
    const int bus = x[i] & y[i];
    if (x[i] != bus) return 1;  // a sent recessive and saw dominant
    if (y[i] != bus) return -1;
  }
  return 0;
}

TEST(ArbitrationKey, LowerIdentifierWins) {
  EXPECT_LT(ArbitrationKey(Frame("080#")), ArbitrationKey(Frame("081#")));
  EXPECT_LT(ArbitrationKey(Frame("000#FF")), ArbitrationKey(Frame("7FF#")));
}

TEST(ArbitrationKey, DataFrameBeatsRemoteFrameWithTheSameIdentifier) {
  EXPECT_LT(ArbitrationKey(Frame("705#")), ArbitrationKey(Frame("705#R")));
  EXPECT_LT(ArbitrationKey(Frame("1ABCDEF0#")), ArbitrationKey(Frame("1ABCDEF0#R")));
  // ...but a remote frame with a lower identifier still beats a data frame.
  EXPECT_LT(ArbitrationKey(Frame("704#R")), ArbitrationKey(Frame("705#01")));
}

// 29-bit 0x04000000 has base identifier 0x100 and extension 0.
TEST(ArbitrationKey, BaseFrameBeatsExtendedFrameWithTheSameBaseIdentifier) {
  // Data frame: RTR (dominant) against SRR (recessive).
  EXPECT_LT(ArbitrationKey(Frame("100#")), ArbitrationKey(Frame("04000000#")));
  // Remote frame: RTR and SRR both recessive, decided by IDE (dominant for a base frame).
  EXPECT_LT(ArbitrationKey(Frame("100#R")), ArbitrationKey(Frame("04000000#")));
  // A lower base identifier wins whatever the format.
  EXPECT_LT(ArbitrationKey(Frame("03FFFFFF#")), ArbitrationKey(Frame("100#")));
  EXPECT_LT(ArbitrationKey(Frame("0FF#R")), ArbitrationKey(Frame("04000000#")));
}

TEST(ArbitrationKey, ExtendedFramesCompareBaseThenExtension) {
  EXPECT_LT(ArbitrationKey(Frame("0FFFFFFF#")), ArbitrationKey(Frame("10000000#")));
  EXPECT_LT(ArbitrationKey(Frame("04000000#")), ArbitrationKey(Frame("04000001#")));
  EXPECT_EQ(ArbitrationKey(Frame("04000001#11")), ArbitrationKey(Frame("04000001#22")));
}

TEST(ArbitrationKey, AgreesWithBitwiseWiredAndArbitration) {
  std::mt19937 rng(11898);
  auto random_frame = [&] {
    CanFrame f;
    const bool ext = (rng() & 1) != 0;
    f.flags = static_cast<std::uint8_t>((ext ? CanFrame::kExtended : 0) |
                                        ((rng() & 3) == 0 ? CanFrame::kRemote : 0));
    // Small identifier ranges so that equal base identifiers and equal ids happen often.
    const std::uint32_t base = static_cast<std::uint32_t>(rng() % 8);
    f.id = ext ? (base << 18 | static_cast<std::uint32_t>(rng() % 4)) : base;
    return f;
  };
  for (int i = 0; i < 20000; ++i) {
    CanFrame a = random_frame(), b = random_frame();
    const int wire = WireArbitration(a, b);
    const auto ka = ArbitrationKey(a), kb = ArbitrationKey(b);
    SCOPED_TRACE(ToCandump(a) + " vs " + ToCandump(b));
    const int by_key = ka < kb ? -1 : (ka > kb ? 1 : 0);
    ASSERT_EQ(by_key, wire);
  }
}

// Given four ports that all submit at the same instant on an idle bus, when the bus runs, then a
// fifth port receives the frames in arbitration order, back to back.
TEST(BrokerArbitration, SimultaneousSubmissionsGoInArbitrationOrder) {
  SimulatedScheduler s;
  Broker broker(s);
  broker.AddBus({.name = "can0", .bitrate = 500'000});
  RecordingSink a, b, c, d, listener;
  const PortId pa = broker.Attach("can0", "a", a);
  const PortId pb = broker.Attach("can0", "b", b);
  const PortId pc = broker.Attach("can0", "c", c);
  const PortId pd = broker.Attach("can0", "d", d);
  broker.Attach("can0", "listener", listener);

  broker.Submit(pa, Frame("04000000#"));  // 29-bit, base 100h
  broker.Submit(pb, Frame("100#R"));      // 11-bit remote 100h
  broker.Submit(pc, Frame("100#01"));     // 11-bit data 100h
  broker.Submit(pd, Frame("0FF#R"));      // lower id, remote
  s.Advance(1s);

  // Back to back from t = 0: each frame ends one exact frame duration after the previous one.
  std::vector<std::string> expected;
  BusTime end{};
  for (const char* f : {"0FF#R", "100#01", "100#R", "04000000#"}) {
    end += FrameTime(f, 500'000);
    expected.push_back(At(f, end));
  }
  EXPECT_EQ(listener.Received(), expected);
  EXPECT_EQ(listener.deliver_calls, 4);  // simulated time: each frame in its own round
}

// Each port's queue is FIFO (one TX buffer, as a Linux CAN driver): only its head competes.
TEST(BrokerArbitration, OnlyTheHeadOfEachPortQueueCompetes) {
  SimulatedScheduler s;
  Broker broker(s);
  broker.AddBus({.name = "can0", .bitrate = 500'000});
  RecordingSink a, b, listener;
  const PortId pa = broker.Attach("can0", "a", a);
  const PortId pb = broker.Attach("can0", "b", b);
  broker.Attach("can0", "listener", listener);
  const CanFrame a_frames[] = {Frame("700#"), Frame("010#")};
  broker.Submit(pa, a_frames);
  broker.Submit(pb, Frame("100#"));
  s.Advance(1s);
  EXPECT_EQ(listener.Ids(), (std::vector<std::string>{"100#", "700#", "010#"}));
}

// Two ports sending the same identifier at once is a configuration error on a real bus; the
// broker lets the earlier submission win, deterministically.
TEST(BrokerArbitration, EqualKeysGoInSubmissionOrder) {
  SimulatedScheduler s;
  Broker broker(s);
  broker.AddBus({.name = "can0"});
  RecordingSink a, b, listener;
  const PortId pa = broker.Attach("can0", "a", a);
  const PortId pb = broker.Attach("can0", "b", b);
  broker.Attach("can0", "listener", listener);
  broker.Submit(pb, Frame("181#02"));
  broker.Submit(pa, Frame("181#01"));
  s.Advance(1s);
  EXPECT_EQ(listener.Ids(), (std::vector<std::string>{"181#02", "181#01"}));
}

}  // namespace
}  // namespace canfleet::broker
