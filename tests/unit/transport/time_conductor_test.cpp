// The broker's side of lock-step virtual time (orchestrator/transport/time_conductor.hpp): rounds,
// the lookahead bound, frames put on the bus at their stamped times, outside inputs between rounds,
// and a node that stops answering; with one G for all (the Conductor tests, as driven and paced
// time run) and with per-node lookahead (the PerNode tests, issue 34). Fake node sessions on a real Broker;
// the event loop is polled, never run against the clock (the grace test uses a grace of 0 ms).
#include "orchestrator/transport/time_conductor.hpp"

#include <gtest/gtest.h>

#include <asio/io_context.hpp>
#include <string>
#include <vector>

#include "bus/physics/frame_timing.hpp"
#include "tests/support/bus_probe.hpp"

namespace canfleet::transport {
namespace {

using namespace std::chrono_literals;
using canfleet::test::Frame;

constexpr std::uint32_t kBitrate = 250'000;

constexpr std::int64_t Ns(Duration d) {
  return d.count();
}
constexpr std::int64_t L = Ns(TimeConductor::kLookahead);

/// A port of a node process (one port unless `clock` names another's), as its NodeSession would
/// present it to the conductor.
class FakeNode final : public GrantedSession, public broker::PortSink {
 public:
  FakeNode(std::string name, TimeConductor& conductor, broker::Broker& broker, std::string clock = {},
           std::string bus = "can0", std::uint64_t attachment = 0, std::uint32_t clock_ports = 1)
      : name_(std::move(name)), bus_(std::move(bus)), conductor_(conductor), broker_(broker) {
    port = broker_.Attach(bus_, name_, *this);
    conductor_.Join(*this, clock.empty() ? name_ : clock, attachment, clock_ports);
  }
  ~FakeNode() override { Leave(); }

  // GrantedSession
  void SendGrant(TimePoint now, TimePoint until, std::span<const std::uint64_t> attachments) override {
    grants.push_back({Ns(now.time_since_epoch()), Ns(until.time_since_epoch())});
    named.emplace_back(attachments.begin(), attachments.end());
    if (answer_at_once) {
      answer_at_once = false;
      Reach(until.time_since_epoch() + answer_period);
    }
  }
  void Evict(const std::string& reason) override {
    evicted = reason;
    Leave();
  }
  const std::string& Label() const override { return name_; }
  const std::string& Bus() const override { return bus_; }
  const Acceptance& Accepting() const override { return accepting; }

  // PortSink
  void Deliver(std::span<const broker::TimedFrame> frames) override {
    for (const auto& f : frames)
      received.push_back(ToCandump(f.frame) + "@" + std::to_string(Ns(f.time)));
    conductor_.Pending(*this);
  }
  void ControllerChanged(const ControllerEvent&) override { conductor_.Pending(*this); }

  /// Answers the last grant as the node would: frames sent during it, then TimeReached, with what
  /// its timers may send when `outlook` says (else anything from `next`).
  bool Reach(std::optional<Duration> next, std::vector<wire::StampedFrame> frames = {},
             const SendOutlook* outlook = nullptr) {
    if (!frames.empty()) conductor_.Submit(*this, port, frames);
    const TimePoint until(Duration(grants.back().second));
    return conductor_.Reached(*this, until, next ? std::optional(TimePoint(*next)) : std::nullopt, outlook);
  }
  /// The same, its timers confined as `confined` says and any other from `any` on.
  bool ReachConfined(std::optional<Duration> next, std::vector<ConfinedSend> confined, Duration any,
                     std::vector<wire::StampedFrame> frames = {}) {
    SendOutlook outlook{TimePoint(any), std::move(confined)};
    return Reach(next, std::move(frames), &outlook);
  }
  void Listen(std::vector<std::uint32_t> ids) { accepting.Set(false, ids); }
  void Leave() {
    if (left_) return;
    left_ = true;
    conductor_.Leave(*this);
    broker_.Detach(port);
  }

  broker::PortId port = 0;
  Acceptance accepting;
  std::vector<std::pair<std::int64_t, std::int64_t>> grants;  ///< (now, until) in ns
  std::vector<std::vector<std::uint64_t>> named;              ///< each grant's attachments
  std::vector<std::string> received;
  std::string evicted;
  /// Answers the next grant from inside SendGrant, its next deadline `answer_period` after the grant.
  bool answer_at_once = false;
  Duration answer_period = 500ms;

 private:
  std::string name_;
  std::string bus_;
  TimeConductor& conductor_;
  broker::Broker& broker_;
  bool left_ = false;
};

class Conductor : public ::testing::Test {
 protected:
  Conductor() { broker.AddBus({.name = "can0", .bitrate = kBitrate}); }
  /// Runs what the event loop has ready (posted rounds, expired zero-length timers).
  void Poll() {
    for (int i = 0; i < 100; ++i) {
      io.restart();
      if (io.poll() == 0) return;
    }
  }

  asio::io_context io;
  GrantedScheduler scheduler;
  broker::Broker broker{scheduler};
  TimeConductor conductor{io, scheduler, broker, {.lookahead = TimeConductorOptions::Lookahead::kGlobal}};
};

// A node that joins may act at once (boot-up): its first grant is to now + the lookahead; then it
// leaps to its next deadline + the lookahead, whatever lies between.
TEST_F(Conductor, ALoneNodeLeapsFromDeadlineToDeadline) {
  FakeNode a("a", conductor, broker);
  Poll();
  ASSERT_EQ(a.grants.size(), 1u);
  EXPECT_EQ(a.grants[0], std::make_pair(std::int64_t{0}, L));
  ASSERT_TRUE(a.Reach(500ms));
  Poll();
  ASSERT_EQ(a.grants.size(), 2u);
  EXPECT_EQ(a.grants[1], std::make_pair(L, Ns(500ms) + L));
}

// A frame a node sends during its grant goes on the bus at its stamped time and reaches the other
// node at its end of frame, which is where the next round starts; that node is granted there.
TEST_F(Conductor, AFrameGoesOnTheBusAtItsStampAndReachesTheOthersAtItsEndOfFrame) {
  FakeNode a("a", conductor, broker), b("b", conductor, broker);
  Poll();
  ASSERT_TRUE(a.Reach(500ms));
  ASSERT_TRUE(b.Reach(std::nullopt));  // b has nothing to do until it hears something
  Poll();
  ASSERT_EQ(a.grants.size(), 2u);
  EXPECT_EQ(b.grants.size(), 1u) << "b has no deadline: it is not woken";
  ASSERT_TRUE(a.Reach(1000ms, {{Frame("705#05"), 500ms}}));
  Poll();
  const std::int64_t end = Ns(500ms + BitTime(CountFrameBits(Frame("705#05")).total(), kBitrate));
  EXPECT_EQ(b.received, (std::vector<std::string>{"705#05@" + std::to_string(end)}));
  ASSERT_EQ(b.grants.size(), 2u);
  EXPECT_EQ(b.grants[1], std::make_pair(end, end + L)) << "the frame ended at the round's start";
}

// A node whose deadline lies beyond the round is not woken; it keeps its place.
TEST_F(Conductor, ANodeNotDueIsNotGranted) {
  FakeNode a("a", conductor, broker), b("b", conductor, broker);
  Poll();
  ASSERT_TRUE(a.Reach(100ms));
  ASSERT_TRUE(b.Reach(300ms));
  Poll();
  EXPECT_EQ(a.grants.back(), std::make_pair(L, Ns(100ms) + L));
  EXPECT_EQ(b.grants.size(), 1u);
  ASSERT_TRUE(a.Reach(400ms));
  Poll();
  EXPECT_EQ(b.grants.back(), std::make_pair(Ns(100ms) + L, Ns(300ms) + L));
  EXPECT_EQ(a.grants.size(), 2u);
}

// Time stands still while held, and without any node; a hold's release lets it go on.
TEST_F(Conductor, TimeStandsStillWhileHeldOrWithoutNodes) {
  Poll();
  EXPECT_EQ(conductor.Stats().rounds, 0u);
  conductor.Hold();
  FakeNode a("a", conductor, broker);
  Poll();
  EXPECT_TRUE(a.grants.empty());
  conductor.Release();
  Poll();
  EXPECT_EQ(a.grants.size(), 1u);
}

// HoldUntilJoined: the fleet's nodes all start at the same simulated time.
TEST_F(Conductor, HoldUntilJoinedStartsTimeWhenTheLastNodeJoins) {
  conductor.HoldUntilJoined(2, std::chrono::milliseconds(60'000));
  FakeNode a("a", conductor, broker);
  Poll();
  EXPECT_TRUE(a.grants.empty());
  FakeNode b("b", conductor, broker);
  Poll();
  ASSERT_EQ(a.grants.size(), 1u);
  ASSERT_EQ(b.grants.size(), 1u);
  EXPECT_EQ(a.grants[0], b.grants[0]);
}

// A process with two ports has joined once both have: it powers on when its last port connects,
// and time started by its first port alone ran on without it (to the fleet's ready timeout, as fast
// as the broker goes, when its other port's Hello was late).
TEST_F(Conductor, HoldUntilJoinedWaitsForEveryPortOfAProcess) {
  broker.AddBus({.name = "can1", .bitrate = kBitrate});
  conductor.HoldUntilJoined(1, std::chrono::milliseconds(60'000));
  FakeNode dl0("dl-can0", conductor, broker, "dl#2", "can0", 7, 2);
  Poll();
  EXPECT_TRUE(dl0.grants.empty()) << "its port on can1 has not joined yet";
  FakeNode dl1("dl-can1", conductor, broker, "dl#2", "can1", 8, 2);
  Poll();
  ASSERT_EQ(dl0.grants.size(), 1u);
  ASSERT_EQ(dl1.grants.size(), 1u);
  EXPECT_EQ(dl0.grants[0], std::make_pair(std::int64_t{0}, L));
  EXPECT_EQ(dl1.grants[0], dl0.grants[0]);
}

// An outside input (a control request) arriving while a round is open waits for its end.
TEST_F(Conductor, AnOutsideInputWaitsForTheEndOfTheOpenRound) {
  FakeNode a("a", conductor, broker);
  Poll();
  bool ran = false;
  conductor.AtBoundary([&] { ran = true; });
  EXPECT_FALSE(ran) << "a round is open";
  ASSERT_TRUE(a.Reach(500ms));
  Poll();
  EXPECT_TRUE(ran);
}

// A node that does not answer within the grace is evicted, and time goes on for the others.
TEST(ConductorGrace, ANodeThatStopsAnsweringIsEvictedAndTimeGoesOn) {
  asio::io_context io;
  GrantedScheduler scheduler;
  broker::Broker broker{scheduler};
  broker.AddBus({.name = "can0", .bitrate = kBitrate});
  TimeConductor conductor{io, scheduler, broker, {.speed = 0, .grace = std::chrono::milliseconds(0)}};
  FakeNode a("a", conductor, broker), b("b", conductor, broker);
  a.answer_at_once = true;  // a answers its first grant; b never does
  for (int i = 0; i < 10 && a.grants.size() < 2; ++i) {
    io.restart();
    io.poll();
  }
  EXPECT_NE(b.evicted.find("no TimeReached within 0 ms"), std::string::npos) << b.evicted;
  ASSERT_GE(a.grants.size(), 2u) << "a's next deadline is granted without b";
  EXPECT_EQ(a.grants[1].second, L + Ns(500ms) + L);
  EXPECT_EQ(b.grants.size(), 1u);
}

// The ports of one process are granted together, and each grant names all of them (their
// Hello.clock_attachment): the process may read one port's grant before another port's HelloReply,
// and must then wait for that port rather than run without it. A port that left is no longer named.
TEST_F(Conductor, EachGrantNamesEveryPortOfItsProcessGrantedWithIt) {
  broker.AddBus({.name = "can1", .bitrate = kBitrate});
  FakeNode q("q", conductor, broker, "q#1", "can0", 1);
  FakeNode dl0("dl-can0", conductor, broker, "dl#2", "can0", 7);
  FakeNode dl1("dl-can1", conductor, broker, "dl#2", "can1", 8);
  Poll();
  ASSERT_EQ(dl0.grants.size(), 1u);
  ASSERT_EQ(dl1.grants.size(), 1u);
  EXPECT_EQ(dl0.grants[0], dl1.grants[0]);
  EXPECT_EQ(dl0.named[0], (std::vector<std::uint64_t>{7, 8}));
  EXPECT_EQ(dl1.named[0], (std::vector<std::uint64_t>{7, 8}));
  EXPECT_EQ(q.named[0], (std::vector<std::uint64_t>{1})) << "another process's ports are not named";
  ASSERT_TRUE(q.Reach(std::nullopt));
  ASSERT_TRUE(dl0.Reach(100ms));
  ASSERT_TRUE(dl1.Reach(100ms));
  dl1.Leave();
  Poll();
  ASSERT_EQ(dl0.grants.size(), 2u);
  EXPECT_EQ(dl0.named[1], (std::vector<std::uint64_t>{7}));
  EXPECT_EQ(dl1.grants.size(), 1u);
}

// A reply that is not for the open round's time, or a second one, is refused.
TEST_F(Conductor, AReplyForAnotherTimeIsRefused) {
  FakeNode a("a", conductor, broker);
  Poll();
  EXPECT_FALSE(conductor.Reached(a, TimePoint(5ms), std::nullopt));
  EXPECT_TRUE(a.Reach(std::nullopt));
  EXPECT_FALSE(a.Reach(std::nullopt)) << "already answered";
}

// Driven time (python/README.md "Virtual time"): time runs only inside Advance, which stops at its
// `until` exactly: rounds are capped there, whatever the nodes' deadlines.
TEST_F(Conductor, DrivenTimeRunsOnlyInsideAnAdvanceAndStopsAtItsEnd) {
  conductor.Drive();
  FakeNode a("a", conductor, broker);
  Poll();
  EXPECT_TRUE(a.grants.empty()) << "driven: no round before an advance";
  std::optional<bool> woken;
  conductor.Advance(TimePoint(300ms), [&](bool w) { woken = w; });
  Poll();
  ASSERT_EQ(a.grants.size(), 1u);
  EXPECT_EQ(a.grants[0], std::make_pair(std::int64_t{0}, L));
  ASSERT_TRUE(a.Reach(500ms));
  Poll();
  ASSERT_EQ(a.grants.size(), 1u) << "its deadline lies beyond the advance: it stands still";
  ASSERT_TRUE(woken.has_value());
  EXPECT_FALSE(*woken);
  EXPECT_EQ(Ns(conductor.Now().time_since_epoch()), Ns(300ms)) << "the advance ends exactly at its until";
  EXPECT_FALSE(conductor.Advancing());
  conductor.Advance(TimePoint(600ms), [&](bool w) { woken = w; });
  Poll();
  ASSERT_EQ(a.grants.size(), 2u);
  EXPECT_EQ(a.grants[1], std::make_pair(Ns(300ms), Ns(500ms) + L));
  ASSERT_TRUE(a.Reach(1000ms));
  Poll();
  EXPECT_EQ(Ns(conductor.Now().time_since_epoch()), Ns(600ms));
}

// Wake (something reached the driver) ends the advance at the end of the round it came in.
TEST_F(Conductor, AWakeEndsTheAdvanceAtTheEndOfItsRound) {
  conductor.Drive();
  FakeNode a("a", conductor, broker);
  std::optional<bool> woken;
  conductor.Advance(TimePoint(10s), [&](bool w) { woken = w; });
  Poll();
  ASSERT_EQ(a.grants.size(), 1u);
  conductor.Wake();  // as a frame for a driven participant does, during the round
  ASSERT_TRUE(a.Reach(500ms));
  Poll();
  ASSERT_TRUE(woken.has_value());
  EXPECT_TRUE(*woken);
  EXPECT_EQ(Ns(conductor.Now().time_since_epoch()), L) << "stopped where the round ended";
  EXPECT_EQ(a.grants.size(), 1u);
}

// With nothing due before its end (no node, no broker timer), an advance gets there at once.
TEST_F(Conductor, AnAdvanceWithNothingDueJumpsToItsEnd) {
  conductor.Drive();
  std::optional<bool> woken;
  conductor.Advance(TimePoint(2s), [&](bool w) { woken = w; });
  Poll();
  ASSERT_TRUE(woken.has_value());
  EXPECT_EQ(Ns(conductor.Now().time_since_epoch()), Ns(2s));
}

// An advance waits while time is held (nodes still joining), and only one runs at a time; time
// that is not driven cannot be advanced.
TEST_F(Conductor, AnAdvanceWaitsForHoldsAndIsRefusedWhenNotDrivenOrBusy) {
  EXPECT_THROW(conductor.Advance(TimePoint(1s), [](bool) {}), std::logic_error);
  conductor.Drive();
  conductor.Hold();
  std::optional<bool> woken;
  conductor.Advance(TimePoint(1s), [&](bool w) { woken = w; });
  EXPECT_THROW(conductor.Advance(TimePoint(2s), [](bool) {}), std::logic_error);
  Poll();
  EXPECT_FALSE(woken.has_value()) << "held";
  conductor.Release();
  Poll();
  ASSERT_TRUE(woken.has_value());
  EXPECT_EQ(Ns(conductor.Now().time_since_epoch()), Ns(1s));
}

// Undrive lets time run on its own again (a fleet stopping), and ends a running advance.
TEST_F(Conductor, UndriveEndsTheAdvanceAndTimeRunsOnItsOwn) {
  conductor.Drive();
  conductor.Hold();
  std::optional<bool> woken;
  conductor.Advance(TimePoint(1s), [&](bool w) { woken = w; });
  conductor.Undrive();
  EXPECT_TRUE(woken.has_value());
  conductor.Release();
  FakeNode a("a", conductor, broker);
  Poll();
  EXPECT_EQ(a.grants.size(), 1u) << "not driven: rounds run without an advance";
}

// A process the fleet (re)starts while time runs: time waits for it to join (its real start-up is
// no simulated time), or for the word that it ended first.
TEST_F(Conductor, TimeWaitsForARestartedProcessToJoin) {
  FakeNode a("a", conductor, broker);
  Poll();
  ASSERT_EQ(a.grants.size(), 1u);
  conductor.HoldUntilProcessJoins("b#2", std::chrono::milliseconds(60'000));
  ASSERT_TRUE(a.Reach(500ms));
  Poll();
  EXPECT_EQ(a.grants.size(), 1u) << "held until b#2 joins";
  FakeNode b("b", conductor, broker, "b#2");
  Poll();
  EXPECT_EQ(b.grants.size(), 1u);
  EXPECT_EQ(b.grants[0].first, L) << "it joined where time stood";

  conductor.HoldUntilProcessJoins("c#3", std::chrono::milliseconds(60'000));
  ASSERT_TRUE(b.Reach(1000ms));
  Poll();
  EXPECT_EQ(a.grants.size(), 1u) << "held until c#3 joins";
  conductor.StopWaitingFor("c#3");  // it ended before it joined
  Poll();
  EXPECT_EQ(a.grants.size(), 2u) << "a's deadline (500 ms) is next";
}

// ---------------------------------------------------------------------------------------------
// Per-node lookahead (issue 34, grant_horizon.hpp): each process to its own horizon.

class PerNode : public Conductor {
 protected:
  PerNode() {
    a.Listen({0x702});  // b's heartbeat
    b.Listen({0x7FF});  // nothing anybody sends
    Poll();
    // Both booted at 0 (pending): each may answer the other at once.
    EXPECT_EQ(a.grants.back(), std::make_pair(std::int64_t{0}, L));
    EXPECT_EQ(b.grants.back(), std::make_pair(std::int64_t{0}, L));
  }
  /// a: TPDO 181h every 100 ms, heartbeat 701h at 500 ms; b: TPDO 182h from 50 ms, heartbeat 702h
  /// at 500 ms; their other timers (a consumer's timeout) at 1500 ms.
  void FirstAnswers() {
    ASSERT_TRUE(a.ReachConfined(100ms, {{0x181, TimePoint(100ms)}, {0x701, TimePoint(500ms)}}, 1500ms));
    ASSERT_TRUE(b.ReachConfined(50ms, {{0x182, TimePoint(50ms)}, {0x702, TimePoint(500ms)}}, 1500ms));
    Poll();
  }
  TimeConductor conductor{io, scheduler, broker};
  FakeNode a{"a", conductor, broker};
  FakeNode b{"b", conductor, broker};
};

// a listens only to b's heartbeat: it runs its own TPDO timers up to b's heartbeat in one grant,
// although b's TPDO comes first. b may hear anything a sends, so it is held to a's horizon.
TEST_F(PerNode, ANodeIsGrantedPastTheDeadlineOfANodeItDoesNotListenTo) {
  FirstAnswers();
  EXPECT_EQ(Ns(conductor.Now().time_since_epoch()), Ns(50ms)) << "the bus runs to the earliest deadline";
  EXPECT_EQ(a.grants.back(), std::make_pair(Ns(50ms), Ns(500ms) + L));
  EXPECT_EQ(b.grants.back(), std::make_pair(Ns(50ms), Ns(500ms) + 2 * L));
}

TEST_F(PerNode, ANodeIsHeldBackByADeadlineOfANodeItListensTo) {
  a.Listen({0x702, 0x182});
  FirstAnswers();
  EXPECT_EQ(a.grants.size(), 1u) << "its next deadline (100 ms) lies beyond b's TPDO (50 ms)";
  EXPECT_EQ(b.grants.back(), std::make_pair(Ns(50ms), Ns(50ms) + 2 * L));
}

// What a applied at its grant's now widened its filter: it stops there (early), and its next grant
// is held to what it now listens to.
TEST_F(PerNode, AFilterChangeStopsTheGrantAtItsNowAndBindsTheNext) {
  FirstAnswers();
  a.Listen({0x702, 0x182});
  SendOutlook outlook{TimePoint(1500ms), {{0x181, TimePoint(100ms)}, {0x701, TimePoint(500ms)}}};
  ASSERT_TRUE(conductor.Reached(a, TimePoint(50ms), TimePoint(100ms), &outlook)) << "an early stop";
  EXPECT_EQ(conductor.Stats().early_stops, 1u);
  // b ran to its grant's end; its TPDOs at 50..450 ms nobody listened to then, its next at 550 ms.
  ASSERT_TRUE(b.ReachConfined(550ms, {{0x182, TimePoint(550ms)}, {0x702, TimePoint(1000ms)}}, 1500ms));
  Poll();
  EXPECT_EQ(a.grants.back(), std::make_pair(Ns(100ms), Ns(550ms) + L)) << "b's next TPDO, which a now hears";
}

// A fault that may corrupt transfers starts at 200 ms (a scenario step: a broker timer, which may
// reach anybody): no grant reaches past it, and from then on the bus is not calm, so each node is
// held to the earliest deadline on it, as with one G for all.
TEST_F(PerNode, AFaultThatStartsMidGrantIsNotGrantedPast) {
  Timer fault(scheduler, [&] { broker.Faults("can0").Add({.action = broker::RuleAction::kCorrupt}); });
  fault.StartAt(TimePoint(200ms));
  FirstAnswers();
  EXPECT_EQ(a.grants.back(), std::make_pair(Ns(50ms), Ns(200ms)));
  EXPECT_EQ(b.grants.back(), std::make_pair(Ns(50ms), Ns(200ms)));
  ASSERT_TRUE(a.ReachConfined(250ms, {{0x181, TimePoint(300ms)}, {0x701, TimePoint(500ms)}}, 1500ms));
  ASSERT_TRUE(b.ReachConfined(300ms, {{0x182, TimePoint(300ms)}, {0x702, TimePoint(500ms)}}, 1500ms));
  Poll();
  EXPECT_EQ(a.grants.back(), std::make_pair(Ns(250ms), Ns(250ms) + L));
  EXPECT_EQ(b.grants.size(), 2u) << "b's deadline (300 ms) lies beyond the lock-step round";
}

// A control request while the processes stand ahead of the bus: it is applied once the bus has
// caught up with the furthest of them (the frontier), never behind one.
TEST_F(PerNode, AnOutsideInputWaitsForTheBusToCatchUpWithTheProcesses) {
  FirstAnswers();
  ASSERT_TRUE(a.ReachConfined(600ms, {{0x181, TimePoint(600ms)}, {0x701, TimePoint(1000ms)}}, 1500ms));
  std::optional<TimePoint> applied;
  conductor.AtBoundary([&] { applied = conductor.Now(); });
  EXPECT_FALSE(applied) << "b's grant is open";
  ASSERT_TRUE(b.ReachConfined(550ms, {{0x182, TimePoint(550ms)}, {0x702, TimePoint(1000ms)}}, 1500ms));
  Poll();
  ASSERT_TRUE(applied);
  EXPECT_EQ(Ns(applied->time_since_epoch()), Ns(500ms) + 2 * L) << "where b stood, the furthest";
}

// Nothing is due anywhere, but a process stands ahead of the bus: an outside input still runs,
// once the bus has caught up with it.
TEST_F(PerNode, AnOutsideInputRunsWhenNothingIsDueAhead) {
  FirstAnswers();
  ASSERT_TRUE(a.Reach(std::nullopt));
  ASSERT_TRUE(b.Reach(std::nullopt));
  Poll();
  std::optional<TimePoint> applied;
  conductor.AtBoundary([&] { applied = conductor.Now(); });
  Poll();
  ASSERT_TRUE(applied) << "it did not wait for ever";
  EXPECT_EQ(Ns(applied->time_since_epoch()), Ns(500ms) + 2 * L) << "where b stood, the furthest";
}

// A frame goes on the bus at its stamp although its sender stands further; its listener is woken
// at its end of frame, where the bus stops.
TEST_F(PerNode, AFrameReachesItsListenerAtItsEndOfFrame) {
  b.Listen({0x181});
  a.Listen({0x7FF});
  ASSERT_TRUE(a.ReachConfined(100ms, {{0x181, TimePoint(100ms)}}, 1500ms));
  ASSERT_TRUE(b.ReachConfined(1000ms, {{0x702, TimePoint(1000ms)}}, 1500ms));
  Poll();
  EXPECT_EQ(a.grants.back(), std::make_pair(Ns(100ms), Ns(100ms) + 2 * L));
  EXPECT_EQ(b.grants.size(), 1u);
  ASSERT_TRUE(a.ReachConfined(200ms, {{0x181, TimePoint(200ms)}}, 1500ms, {{Frame("181#01"), 100ms}}));
  Poll();
  const std::int64_t end = Ns(100ms + BitTime(CountFrameBits(Frame("181#01")).total(), kBitrate));
  EXPECT_EQ(b.received, (std::vector<std::string>{"181#01@" + std::to_string(end)}));
  EXPECT_EQ(b.grants.back(), std::make_pair(end, end + 2 * L));
  EXPECT_EQ(conductor.Stats().causality_errors, 0u);
}

}  // namespace
}  // namespace canfleet::transport
