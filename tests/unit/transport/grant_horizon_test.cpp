// Per-node lookahead (orchestrator/transport/grant_horizon.hpp, issue 34): how far each node
// process may be granted, from what it listens to and when the others may send it.
#include "orchestrator/transport/grant_horizon.hpp"

#include <gtest/gtest.h>

#include <deque>
#include <initializer_list>
#include <vector>

namespace canfleet::transport {
namespace {

using namespace std::chrono_literals;

constexpr Duration L = 24us;

TimePoint At(Duration d) {
  return TimePoint(d);
}

/// A small fleet on bus 0 (and 1), built up by the test, then computed.
class Horizons : public ::testing::Test {
 protected:
  struct Node {
    bool pending = false;
    Duration reacts_after{};
    std::optional<TimePoint> next;
    std::optional<TimePoint> any;
    std::vector<ConfinedSend> confined;
    std::vector<std::size_t> buses{0};
    Acceptance acceptance;  // one filter for all its ports
    std::vector<HorizonPort> ports;
  };
  Horizons() {
    HorizonBus calm;
    calm.calm = true;
    buses.assign(2, calm);
  }

  Node& Add(std::initializer_list<std::uint32_t> listens, std::optional<Duration> next,
            std::vector<ConfinedSend> confined = {}, std::optional<Duration> any = std::nullopt) {
    Node& n = fleet.emplace_back();
    const std::vector<std::uint32_t> ids(listens);
    n.acceptance.Set(false, ids);
    if (next) n.next = At(*next);
    n.any = any ? std::optional(At(*any)) : n.next;
    n.confined = std::move(confined);
    return n;
  }
  /// The node listens only to `heartbeat`, which it answers with nothing before 1500 ms.
  static void ListenPassively(Node& n, std::uint32_t heartbeat) {
    const std::vector<std::uint32_t> ids{heartbeat};
    const std::vector<Acceptance::Passive> passive{{heartbeat, 1500ms}};
    n.acceptance.Set(false, ids, passive);
  }
  std::optional<TimePoint> Compute(TimePoint now = TimePoint{}, std::optional<TimePoint> cap = std::nullopt,
                                   std::vector<KnownFrame> known = {}) {
    std::vector<HorizonNode> nodes;
    for (Node& n : fleet) {
      n.ports.clear();
      for (const std::size_t b : n.buses)
        n.ports.push_back({b, &n.acceptance});
      nodes.push_back({n.pending, n.reacts_after, n.next, n.any, n.confined, n.ports});
    }
    horizons.Compute(now, L, cap, buses, nodes, known);
    return horizons.Of(0);
  }

  std::deque<Node> fleet;
  std::vector<HorizonBus> buses;
  GrantHorizons horizons;
};

// Node n sends its TPDO (180h + n) and its heartbeat (700h + n) from confined timers; its other
// timers (a heartbeat consumer's timeout) lie far ahead.
ConfinedSend Tpdo(std::uint32_t n, Duration at) {
  return {0x180 + n, At(at)};
}
ConfinedSend Heartbeat(std::uint32_t n, Duration at) {
  return {0x700 + n, At(at), true};
}
constexpr Duration kFar = 1500ms;

// Node 0 listens to node 1's heartbeat; node 1's TPDO timer fires first, but node 0 does not
// listen to it: node 0 reaches node 1's heartbeat, plus the lookahead.
TEST_F(Horizons, ANodeIsGrantedPastTheDeadlineOfANodeItDoesNotListenTo) {
  Add({0x701}, 20ms, {Tpdo(0, 20ms), Heartbeat(0, 300ms)}, kFar);
  Add({0x7FF}, 10ms, {Tpdo(1, 10ms), Heartbeat(1, 500ms)}, kFar);
  EXPECT_EQ(Compute(), At(500ms + L));
  EXPECT_EQ(horizons.Of(1), At(500ms + 2 * L)) << "node 0 may answer node 1's heartbeat with anything";
}

// Each consumes the other's heartbeat and may answer it with anything (its own heartbeat too):
// a ring of consumers is held to the earliest heartbeat on it, plus the lookahead once per link.
TEST_F(Horizons, ARingOfHeartbeatConsumersIsHeldToItsEarliestHeartbeat) {
  Add({0x701}, 20ms, {Tpdo(0, 20ms), Heartbeat(0, 300ms)}, kFar);
  Add({0x700}, 10ms, {Tpdo(1, 10ms), Heartbeat(1, 500ms)}, kFar);
  EXPECT_EQ(Compute(), At(300ms + 2 * L));
  EXPECT_EQ(horizons.Of(1), At(300ms + L));
}

TEST_F(Horizons, ANodeIsHeldBackByADeadlineOfANodeItListensTo) {
  Add({0x701, 0x181}, 20ms, {Tpdo(0, 20ms), Heartbeat(0, 300ms)}, kFar);
  Add({0x7FF}, 10ms, {Tpdo(1, 10ms), Heartbeat(1, 500ms)}, kFar);
  EXPECT_EQ(Compute(), At(10ms + L));
}

TEST_F(Horizons, AFilterChangeMovesTheHorizon) {
  Add({0x701}, 20ms, {Tpdo(0, 20ms), Heartbeat(0, 300ms)}, kFar);
  Add({0x7FF}, 10ms, {Tpdo(1, 10ms), Heartbeat(1, 500ms)}, kFar);
  EXPECT_EQ(Compute(), At(500ms + L));
  const std::vector<std::uint32_t> wider{0x701, 0x181};
  fleet[0].acceptance.Set(false, wider);
  EXPECT_EQ(Compute(), At(10ms + L));
  fleet[0].acceptance.Set(true, {});
  EXPECT_EQ(Compute(), At(10ms + L)) << "every frame: the sender's earliest timer";
}

// A fault that may corrupt transfers (or any port that is not error-active) makes the bus not
// calm: then every process on it may be reached by anything anyone sends, its own frames included.
TEST_F(Horizons, ABusThatIsNotCalmHoldsEveryNodeToTheEarliestTimerOnIt) {
  Add({0x701}, 20ms, {Tpdo(0, 20ms), Heartbeat(0, 300ms)}, kFar);
  Add({0x7FF}, 10ms, {Tpdo(1, 10ms), Heartbeat(1, 500ms)}, kFar);
  EXPECT_EQ(Compute(), At(500ms + L));
  buses[0].calm = false;
  EXPECT_EQ(Compute(), At(10ms + L));
  EXPECT_EQ(horizons.Of(1), At(10ms + L)) << "its own frame may fail and change its controller's state";
}

TEST_F(Horizons, AnUnconfinedTimerMayBringAnything) {
  Add({0x701}, 20ms, {Tpdo(0, 20ms)}, kFar);
  Add({0x700}, 10ms, {Tpdo(1, 10ms), Heartbeat(1, 500ms)}, 50ms);
  EXPECT_EQ(Compute(), At(50ms + L));
  fleet[1].any.reset();
  fleet[1].confined.clear();
  EXPECT_EQ(Compute(), At(10ms + L)) << "a node that confines nothing: its earliest timer";
}

// What reaches a node may make it send anything at once: the bound travels along the filters.
TEST_F(Horizons, ABoundTravelsThroughTheNodesThatListen) {
  Add({0x702}, 900ms, {Tpdo(0, 900ms)}, kFar);       // 0 listens to 2's heartbeat
  Add({0x7FF}, 10ms, {Tpdo(1, 10ms)}, kFar);         // 1 sends 181h at 10 ms
  Add({0x181}, 800ms, {Heartbeat(2, 800ms)}, kFar);  // 2 listens to 181h
  EXPECT_EQ(Compute(), At(10ms + 2 * L)) << "2 may answer 1's TPDO with anything, 702h included";
  EXPECT_EQ(horizons.Of(2), At(10ms + L));
}

TEST_F(Horizons, APendingNodeMayAnswerAtOnce) {
  Add({0x701}, 900ms, {Tpdo(0, 900ms)}, kFar);
  Node& sender = Add({0x7FF}, 900ms, {Heartbeat(1, 500ms)}, kFar);
  EXPECT_EQ(Compute(At(5ms)), At(500ms + L));
  sender.pending = true;
  EXPECT_EQ(Compute(At(5ms)), At(5ms + L));
}

TEST_F(Horizons, AFrameOnTheBusThatANodeListensToBoundsIt) {
  Add({0x701}, 900ms, {Tpdo(0, 900ms)}, kFar);
  Add({0x7FF}, 900ms, {Heartbeat(1, 500ms)}, kFar);
  buses[0].next_event = At(3ms);
  buses[0].pending = {{0x181, false}};
  EXPECT_EQ(Compute(), At(500ms + L)) << "it does not listen to 181h";
  buses[0].pending = {{0x181, false}, {0x701, false}};
  EXPECT_EQ(Compute(), At(3ms));
  buses[0].pending = {{Acceptance::kExtendedKey, false}};
  EXPECT_EQ(Compute(), At(3ms)) << "29-bit frames always pass the filter";
}

TEST_F(Horizons, TheCapAndTheOtherBusesOfAProcess) {
  Add({0x701}, 900ms, {Tpdo(0, 900ms)}, kFar);
  Add({0x7FF}, 900ms, {Heartbeat(1, 500ms)}, kFar);
  EXPECT_EQ(Compute(TimePoint{}, At(100ms)), At(100ms)) << "a scenario step or a fault's timer";
  Node& other = Add({0x7FF}, 5ms);  // confines nothing
  other.buses = {1};
  fleet[0].buses = {0, 1};
  const std::vector<std::uint32_t> listens{0x701, 0x703};
  fleet[0].acceptance.Set(false, listens);
  EXPECT_EQ(Compute(), At(5ms + L)) << "node 0 listens on bus 1 too, where node 2 may send anything";
  EXPECT_EQ(horizons.Of(1), At(5ms + 2 * L)) << "node 0 may answer on bus 0 what it hears from node 2";
}

// A heartbeat consumer answers a heartbeat with nothing (it re-arms its timeout): the ring of
// consumers is no longer held to its earliest heartbeat; each node reaches its producer's.
TEST_F(Horizons, PassiveHeartbeatsDoNotTravelAroundTheRing) {
  Add({0x701}, 20ms, {Tpdo(0, 20ms), Heartbeat(0, 300ms)}, kFar);
  Add({0x702}, 10ms, {Tpdo(1, 10ms), Heartbeat(1, 100ms)}, kFar);
  Add({0x700}, 30ms, {Tpdo(2, 30ms), Heartbeat(2, 200ms)}, kFar);
  Compute();
  EXPECT_EQ(horizons.Of(2), At(100ms + 2 * L)) << "not passive: the earliest heartbeat, around the ring";
  for (std::uint32_t n = 0; n < 3; ++n) {
    ListenPassively(fleet[n], 0x700 + (n + 1) % 3);
  }
  EXPECT_EQ(Compute(), At(100ms + L));
  EXPECT_EQ(horizons.Of(1), At(200ms + L));
  EXPECT_EQ(horizons.Of(2), At(300ms + L));
}

// A boot-up is no heartbeat: what a node sends on input (or from an unconfined timer) on a passive
// identifier may still be answered at once.
TEST_F(Horizons, APassiveIdentifierSentOnInputIsAnsweredAtOnce) {
  Add({0x701}, 900ms, {Tpdo(0, 900ms)}, kFar);
  Node& sender = Add({0x7FF}, 900ms, {Heartbeat(1, 500ms)}, kFar);
  ListenPassively(fleet[0], 0x701);
  Add({0x180}, 900ms, {Heartbeat(2, 800ms)}, kFar);  // hears node 0's TPDO
  EXPECT_EQ(Compute(), At(500ms + L));
  EXPECT_EQ(horizons.Of(2), At(900ms + L)) << "node 0 answers the heartbeat only 1500 ms later";
  sender.pending = true;
  EXPECT_EQ(Compute(At(5ms)), At(5ms + L));
  EXPECT_EQ(horizons.Of(2), At(5ms + L)) << "a pending node may send anything, a boot-up too";
}

// Node 1 ran ahead of the bus and sent its heartbeat at 10 ms (not on the bus yet); its timer's
// next is at 510 ms. Node 0 hears the one sent, even though it only re-arms its timeout.
TEST_F(Horizons, AFrameSentAheadOfTheBusReachesItsListeners) {
  Add({0x701}, 900ms, {Tpdo(0, 900ms)}, kFar);
  Add({0x7FF}, 900ms, {Heartbeat(1, 510ms)}, kFar);
  ListenPassively(fleet[0], 0x701);
  EXPECT_EQ(Compute(), At(510ms + L));
  EXPECT_EQ(Compute(TimePoint{}, std::nullopt, {{0, 1, 0x701, At(10ms), true}}), At(10ms + L));
  EXPECT_EQ(Compute(TimePoint{}, std::nullopt, {{0, 1, 0x181, At(10ms), false}}), At(510ms + L))
      << "a frame it does not listen to";
  EXPECT_EQ(Compute(TimePoint{}, std::nullopt, {{0, 1, Acceptance::kExtendedKey, At(10ms), false}}),
            At(10ms + L))
      << "a 29-bit frame passes every filter";
}

// A node woken by a heartbeat it only watches (pending, but passive for 1500 ms) does not hold the
// others to now: it answers nothing before its delay.
TEST_F(Horizons, ANodeWokenByAPassiveHeartbeatDoesNotHoldTheOthers) {
  Add({0x701}, 900ms, {Tpdo(0, 900ms)}, kFar);
  Add({0x7FF}, 900ms, {Heartbeat(1, 510ms)}, kFar);
  ListenPassively(fleet[0], 0x701);
  fleet[0].pending = true;
  EXPECT_EQ(Compute(At(10ms)), At(10ms + 2 * L));
  EXPECT_EQ(horizons.Of(1), At(10ms + L)) << "pending, node 0 may answer at once";
  fleet[0].reacts_after = 1500ms;
  EXPECT_EQ(Compute(At(10ms)), At(510ms + L));
  EXPECT_EQ(horizons.Of(1), At(kFar + L)) << "node 0 answers nothing before its other timers";
}

TEST_F(Horizons, NothingReachesANodeThatListensToNothing) {
  Add({}, 900ms);
  Add({0x700}, 10ms);
  EXPECT_EQ(Compute(), std::nullopt);
}

}  // namespace
}  // namespace canfleet::transport
