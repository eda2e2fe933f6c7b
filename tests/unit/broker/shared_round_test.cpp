// One shared buffer per round for every receiver (issue 4, performance): each frame of a round is
// written once, every port receives runs of it, with per-receiver exceptions (its own frames,
// fault-stage drops and delays, error frames for monitors only). Sinks that only implement
// Deliver still get one contiguous batch per round.
#include <gtest/gtest.h>

#include <set>

#include "orchestrator/broker/broker.hpp"
#include "tests/unit/broker/broker_test_support.hpp"

namespace canfleet::broker {
namespace {

using namespace test;

/// Records what DeliverShared hands over; Deliver must not be called (the broker calls
/// DeliverShared, this sink does not forward to Deliver).
class SharedSink : public PortSink {
 public:
  void Deliver(std::span<const TimedFrame> batch) override {
    legacy_calls += static_cast<int>(batch.size()) + 1;
  }
  void DeliverShared(const SharedRound& round, std::span<const FrameRun> runs) override {
    ++calls;
    round_ids.push_back(round.Id());
    buffers.insert(round.Frames().data());
    run_counts.push_back(runs.size());
    std::uint32_t last_end = 0;
    for (const FrameRun& run : runs) {
      EXPECT_LT(run.begin, run.end);
      EXPECT_GE(run.begin, last_end);
      EXPECT_LE(run.end, round.Frames().size());
      last_end = run.end;
      for (std::uint32_t i = run.begin; i < run.end; ++i)
        frames.push_back(round.Frames()[i]);
    }
  }
  void ControllerChanged(const ControllerEvent&) override {}
  void TxConfirmed(std::span<const TimedFrame> batch) override { confirmed += batch.size(); }

  std::vector<std::string> Ids() const {
    std::vector<std::string> out;
    for (const auto& f : frames)
      out.push_back(ToCandump(f.frame) + (f.frame.error() ? "!" : ""));
    return out;
  }

  std::vector<TimedFrame> frames;
  std::vector<std::uint64_t> round_ids;
  std::vector<std::size_t> run_counts;
  std::set<const TimedFrame*> buffers;
  std::size_t confirmed = 0;
  int calls = 0;
  int legacy_calls = 0;
};

// Four ports each send two frames in one round: every receiver reads the same buffer (same round,
// same storage), minus its own frames; a port whose frames sit in the middle gets two runs.
TEST(SharedRound, EveryReceiverReadsOneBufferMinusItsOwnFrames) {
  SimulatedScheduler s;
  Broker broker(s);
  broker.AddBus({.name = "fast", .paced = false});
  SharedSink sinks[4];
  PortId ids[4];
  for (int i = 0; i < 4; ++i)
    ids[i] = broker.Attach("fast", "p" + std::to_string(i), sinks[i]);
  for (int i = 0; i < 4; ++i) {
    const CanFrame frames[] = {Frame("10" + std::to_string(i) + "#01"),
                               Frame("10" + std::to_string(i) + "#02")};
    broker.Submit(ids[i], frames);
  }
  s.Advance(0ns);
  const std::vector<std::string> all = {"100#01", "100#02", "101#01", "101#02",
                                        "102#01", "102#02", "103#01", "103#02"};
  std::set<const TimedFrame*> buffers;
  for (int i = 0; i < 4; ++i) {
    SCOPED_TRACE(i);
    std::vector<std::string> expected;
    for (std::size_t k = 0; k < all.size(); ++k)
      if (k / 2 != static_cast<std::size_t>(i)) expected.push_back(all[k]);
    EXPECT_EQ(sinks[i].Ids(), expected);
    EXPECT_EQ(sinks[i].calls, 1);
    EXPECT_EQ(sinks[i].legacy_calls, 0);
    EXPECT_EQ(sinks[i].confirmed, 2u);
    // The first and the last sender's frames are at an end of the round: one run; the others'
    // cut it in two.
    EXPECT_EQ(sinks[i].run_counts, (std::vector<std::size_t>{i == 0 || i == 3 ? 1u : 2u}));
    EXPECT_EQ(sinks[i].round_ids, sinks[0].round_ids);
    buffers.insert(sinks[i].buffers.begin(), sinks[i].buffers.end());
    EXPECT_EQ(broker.Port(ids[i]).rx_frames, 6u);
  }
  EXPECT_EQ(buffers.size(), 1u);  // one buffer for all four
  EXPECT_EQ(broker.Stats("fast").deliveries, 24u);

  // The next round is another round (a sink caching per round must not reuse the old one).
  broker.Submit(ids[0], Frame("100#03"));
  s.Advance(1ns);
  EXPECT_EQ(sinks[1].Ids().back(), "100#03");
  ASSERT_EQ(sinks[1].round_ids.size(), 2u);
  EXPECT_NE(sinks[1].round_ids[0], sinks[1].round_ids[1]);
}

// The fault stage's per-receiver decisions and the monitor's error frames are exceptions to the
// shared round: each receiver gets exactly what it got when every port had its own copy. Mixed
// sinks on one bus: b and c read the shared round, the monitor only implements Deliver.
TEST(SharedRound, PerReceiverExceptions) {
  SimulatedScheduler s;
  Broker broker(s);
  broker.AddBus({.name = "can0", .bitrate = 125'000});
  SharedSink a, b, c;
  RecordingSink monitor{&s};
  const PortId pa = broker.Attach("can0", "a", a);
  const PortId pb = broker.Attach("can0", "b", b);
  const PortId pc = broker.Attach("can0", "c", c);
  const PortId pm = broker.Attach("can0", "m", monitor, {.listen_only = true, .error_frames = true});
  FaultStage& faults = broker.Faults("can0");
  faults.Add({.id = 0x181, .mask = 0x7FF, .receivers = {pb}, .action = RuleAction::kDrop});
  faults.Add({.id = 0x182, .mask = 0x7FF, .receivers = {pc}, .action = RuleAction::kDelay, .delay = 20ms});
  faults.Add({.id = 0x183, .mask = 0x7FF, .action = RuleAction::kCorrupt, .count = 1});
  const CanFrame frames[] = {Frame("181#01"), Frame("182#02"), Frame("183#03")};
  broker.Submit(pa, frames);
  s.Advance(100ms);

  EXPECT_TRUE(a.frames.empty());
  EXPECT_EQ(a.confirmed, 3u);
  EXPECT_EQ(b.Ids(), (std::vector<std::string>{"182#02", "183#03"}));
  EXPECT_EQ(c.Ids(), (std::vector<std::string>{"181#01", "183#03", "182#02"}));
  EXPECT_EQ(monitor.Ids(), (std::vector<std::string>{"181#01", "182#02", "183#", "183#03"}));
  EXPECT_TRUE(monitor.frames[2].frame.error());
  for (const SharedSink* sink : {&a, &b, &c})
    EXPECT_EQ(sink->legacy_calls, 0);
  // Times never go backwards for a receiver; the delayed frame carries its delivery time.
  for (const std::vector<TimedFrame>* frames_of : {&b.frames, &c.frames, &monitor.frames})
    for (std::size_t i = 1; i < frames_of->size(); ++i)
      EXPECT_LE((*frames_of)[i - 1].time, (*frames_of)[i].time);
  EXPECT_GE(c.frames.back().time - b.frames.front().time, BusTime(20ms) - BusTime(1ms));

  // Counters as before: error frames are not received frames, a delayed frame counts once.
  EXPECT_EQ(broker.Port(pb).rx_frames, 2u);
  EXPECT_EQ(broker.Port(pb).fault_drops, 1u);
  EXPECT_EQ(broker.Port(pc).rx_frames, 3u);
  EXPECT_EQ(broker.Port(pm).rx_frames, 3u);
  EXPECT_EQ(broker.Port(pa).rx_frames, 0u);
  EXPECT_EQ(broker.Stats("can0").deliveries, 8u);
}

// A sink that only implements Deliver gets one contiguous batch per round even when its share of
// the round is cut in several runs (here by its own frames).
TEST(SharedRound, DeliverOnlySinksGetOneBatchPerRound) {
  SimulatedScheduler s;
  Broker broker(s);
  broker.AddBus({.name = "fast", .paced = false});
  RecordingSink a{&s}, b{&s};
  const PortId pa = broker.Attach("fast", "a", a);
  const PortId pb = broker.Attach("fast", "b", b);
  broker.Submit(pa, Frame("101#01"));
  broker.Submit(pb, Frame("102#01"));
  broker.Submit(pa, Frame("101#02"));
  broker.Submit(pb, Frame("102#02"));
  broker.Submit(pa, Frame("101#03"));
  s.Advance(0ns);
  EXPECT_EQ(b.Ids(), (std::vector<std::string>{"101#01", "101#02", "101#03"}));
  EXPECT_EQ(b.deliver_calls, 1);
  EXPECT_EQ(a.Ids(), (std::vector<std::string>{"102#01", "102#02"}));
  EXPECT_EQ(a.deliver_calls, 1);
}

// A port attached from inside a round (by a sink) receives nothing of that round; one that
// detaches inside it receives nothing more.
TEST(SharedRound, PortsAttachedDuringARoundStartAtTheNextFrame) {
  SimulatedScheduler s;
  Broker broker(s);
  broker.AddBus({.name = "fast", .paced = false});
  RecordingSink a{&s}, b{&s}, late{&s};
  const PortId pa = broker.Attach("fast", "a", a);
  broker.Attach("fast", "b", b);
  PortId plate = 0;
  b.on_deliver = [&](std::span<const TimedFrame>) {
    if (plate == 0) plate = broker.Attach("fast", "late", late);
  };
  const CanFrame frames[] = {Frame("181#01"), Frame("181#02")};
  broker.Submit(pa, frames);
  s.Advance(0ns);
  EXPECT_EQ(b.Ids().size(), 2u);
  EXPECT_TRUE(late.frames.empty());
  broker.Submit(pa, Frame("181#03"));
  s.Advance(1ns);
  EXPECT_EQ(late.Ids(), (std::vector<std::string>{"181#03"}));
  EXPECT_EQ(broker.Port(plate).rx_frames, 1u);
}

}  // namespace
}  // namespace canfleet::broker
