// A node process's side of lock-step virtual time (bus/broker_client/virtual_time_client.hpp): what
// the broker sent is applied at the grant's time, timers run to the grant's end, and a process with
// two ports runs only once every port its grant names is granted.
#include "bus/broker_client/virtual_time_client.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace canfleet {
namespace {

using namespace std::chrono_literals;

struct FakePort : GrantedPort {
  explicit FakePort(std::string name, std::vector<std::string>& log, GrantedScheduler& s)
      : name_(std::move(name)), log_(log), s_(s) {}
  void ApplyHeld() override {
    log_.push_back(name_ + " apply at " + std::to_string(s_.Now().time_since_epoch().count()));
  }
  bool AcceptanceChanged() override { return filter_changed; }
  void Reached(TimePoint time, std::optional<TimePoint> next, const TimerOutlook& outlook) override {
    log_.push_back(name_ + " reached " + std::to_string(time.time_since_epoch().count()) +
                   (next ? " next " + std::to_string(next->time_since_epoch().count()) : " idle"));
    last_outlook = outlook;
  }
  bool filter_changed = false;
  TimerOutlook last_outlook;
  std::string name_;
  std::vector<std::string>& log_;
  GrantedScheduler& s_;
};

// A grant: held items at the grant's now, then the node's timers up to its end, then TimeReached
// with the next deadline.
TEST(VirtualTimeClient, AGrantAppliesWhatWasHeldAtItsTimeThenRunsTimersThenReports) {
  GrantedScheduler s;
  std::vector<std::string> log;
  Timer heartbeat(s, [&] {
    log.push_back("heartbeat at " + std::to_string(s.Now().time_since_epoch().count()));
    heartbeat.StartAfter(500ns);
  });
  VirtualTimeClient client(s, "quad-5#1", 1);
  FakePort port("p1", log, s);
  client.Connected(0, port, TimePoint(100ns));
  heartbeat.StartAfter(500ns);  // at 600
  client.Granted(0, TimePoint(200ns), TimePoint(700ns));
  EXPECT_EQ(log,
            (std::vector<std::string>{"p1 apply at 200", "heartbeat at 600", "p1 reached 700 next 1100"}));
  EXPECT_EQ(client.Rounds(), 1u);
}

// Two ports: nothing runs until both have their grant; both then report, in port order.
TEST(VirtualTimeClient, ATwoPortProcessRunsOnceEveryConnectedPortIsGranted) {
  GrantedScheduler s;
  std::vector<std::string> log;
  VirtualTimeClient client(s, "valve#2", 2);
  FakePort a("a", log, s), b("b", log, s);
  client.Connected(0, a, TimePoint(0ns));
  client.Connected(1, b, TimePoint(0ns));
  client.Granted(1, TimePoint(0ns), TimePoint(24ns));
  EXPECT_TRUE(log.empty());
  client.Granted(0, TimePoint(0ns), TimePoint(24ns));
  EXPECT_EQ(log, (std::vector<std::string>{"a apply at 0", "b apply at 0", "a reached 24 idle",
                                           "b reached 24 idle"}));
}

// A port that disconnects is no longer waited for (a broker that names no connections in its
// grants: every connected port is).
TEST(VirtualTimeClient, APortThatDisconnectsIsNoLongerWaitedFor) {
  GrantedScheduler s;
  std::vector<std::string> log;
  VirtualTimeClient client(s, "valve#3", 2);
  FakePort a("a", log, s), b("b", log, s);
  client.Connected(0, a, TimePoint(0ns));
  client.Connected(1, b, TimePoint(0ns));
  client.Granted(0, TimePoint(0ns), TimePoint(24ns));
  client.Disconnected(1);
  EXPECT_EQ(log, (std::vector<std::string>{"a apply at 0", "a reached 24 idle"}));
}

// The race of a process with two ports (the data logger on can0 and can1): the broker joined both
// before the round and granted both, each grant naming both connections; the node read port 1's
// HelloReply and grant before port 0's HelloReply. It waits for port 0 instead of running without
// it (which left port 0's grant unanswered: the broker closed it after 10 s of real time).
TEST(VirtualTimeClient, AGrantReadBeforeAnotherPortsHelloReplyWaitsForThatPortsGrant) {
  GrantedScheduler s;
  std::vector<std::string> log;
  VirtualTimeClient client(s, "datalogger#5", 2);
  FakePort a("a", log, s), b("b", log, s);
  const std::uint64_t a_id = client.Attaching(0);
  const std::uint64_t b_id = client.Attaching(1);
  ASSERT_NE(a_id, b_id);
  const std::vector<std::uint64_t> both{a_id, b_id};
  client.Connected(1, b, TimePoint(0ns));
  client.Granted(1, TimePoint(0ns), TimePoint(24ns), both);
  EXPECT_TRUE(log.empty()) << "port 0 is named by the grant: its HelloReply and grant are on their way";
  EXPECT_EQ(client.Rounds(), 0u);
  client.Connected(0, a, TimePoint(0ns));
  EXPECT_TRUE(log.empty());
  client.Granted(0, TimePoint(0ns), TimePoint(24ns), both);
  EXPECT_EQ(log, (std::vector<std::string>{"a apply at 0", "b apply at 0", "a reached 24 idle",
                                           "b reached 24 idle"}));
  EXPECT_EQ(client.Rounds(), 1u);
}

// A port whose Hello the broker had not accepted before the round is not granted in it, and not
// waited for: the broker accepts it only once this round is answered.
TEST(VirtualTimeClient, APortStillAttachingThatTheGrantDoesNotNameIsNotWaitedFor) {
  GrantedScheduler s;
  std::vector<std::string> log;
  VirtualTimeClient client(s, "datalogger#6", 2);
  FakePort a("a", log, s), b("b", log, s);
  const std::uint64_t a_id = client.Attaching(0);
  client.Attaching(1);
  client.Connected(0, a, TimePoint(0ns));
  client.Granted(0, TimePoint(0ns), TimePoint(24ns), std::vector<std::uint64_t>{a_id});
  EXPECT_EQ(log, (std::vector<std::string>{"a apply at 0", "a reached 24 idle"}));
}

// A named port whose attempt fails, or that lost the connection the grant named and is attaching
// again, is no longer waited for: the broker no longer waits for it either.
TEST(VirtualTimeClient, ANamedPortWhoseConnectionIsGoneIsNoLongerWaitedFor) {
  GrantedScheduler s;
  std::vector<std::string> log;
  VirtualTimeClient client(s, "datalogger#7", 2);
  FakePort a("a", log, s), b("b", log, s);
  const std::uint64_t a_id = client.Attaching(0);
  const std::uint64_t b_id = client.Attaching(1);
  client.Connected(1, b, TimePoint(0ns));
  client.Granted(1, TimePoint(0ns), TimePoint(24ns), std::vector<std::uint64_t>{a_id, b_id});
  EXPECT_TRUE(log.empty());
  client.Disconnected(0);  // port 0's attempt failed before its HelloReply
  EXPECT_EQ(log, (std::vector<std::string>{"b apply at 0", "b reached 24 idle"}));

  log.clear();
  const std::uint64_t a_again = client.Attaching(0);
  EXPECT_NE(a_again, a_id) << "a new attempt is a new connection";
  client.Granted(1, TimePoint(24ns), TimePoint(48ns), std::vector<std::uint64_t>{a_id, b_id});
  EXPECT_EQ(log, (std::vector<std::string>{"b apply at 24", "b reached 48 idle"}))
      << "the grant names port 0's lost connection, not the new attempt";
}

// A connected port the grant does not name (the broker closed it; the node has not read that yet)
// is neither waited for nor answered.
TEST(VirtualTimeClient, AConnectedPortTheGrantDoesNotNameIsNotPartOfTheRound) {
  GrantedScheduler s;
  std::vector<std::string> log;
  VirtualTimeClient client(s, "datalogger#8", 2);
  FakePort a("a", log, s), b("b", log, s);
  client.Attaching(0);
  const std::uint64_t b_id = client.Attaching(1);
  client.Connected(0, a, TimePoint(0ns));
  client.Connected(1, b, TimePoint(0ns));
  client.Granted(1, TimePoint(0ns), TimePoint(24ns), std::vector<std::uint64_t>{b_id});
  EXPECT_EQ(log, (std::vector<std::string>{"b apply at 0", "b reached 24 idle"}));
}

// A node joining a running bus starts at the bus's time.
TEST(VirtualTimeClient, ANodeJoiningARunningBusStartsAtItsTime) {
  GrantedScheduler s;
  std::vector<std::string> log;
  VirtualTimeClient client(s, "quad#4", 1);
  FakePort a("a", log, s);
  client.Connected(0, a, TimePoint(3600s));
  EXPECT_EQ(s.Now(), TimePoint(3600s));
}

// Per-node lookahead (issue 34): TimeReached says what the timers may send; a confined timer only
// its identifier.
TEST(VirtualTimeClient, TimeReachedSaysWhatTheTimersMaySend) {
  GrantedScheduler s;
  std::vector<std::string> log;
  Timer heartbeat(s, [] {});
  Timer tpdo(s, [] {});
  Timer tick(s, [] {});
  heartbeat.Confine(0x705);
  tpdo.Confine(0x185);
  VirtualTimeClient client(s, "quad-5#1", 1);
  FakePort port("p1", log, s);
  client.Connected(0, port, TimePoint(0ns));
  heartbeat.StartAt(TimePoint(500ms));
  tpdo.StartAt(TimePoint(100ms));
  tick.StartAt(TimePoint(1500ms));
  client.Granted(0, TimePoint(0ns), TimePoint(24us));
  EXPECT_EQ(port.last_outlook.unconfined, TimePoint(1500ms));
  EXPECT_EQ(port.last_outlook.confined, (std::vector<std::pair<std::uint32_t, TimePoint>>{
                                            {0x185, TimePoint(100ms)}, {0x705, TimePoint(500ms)}}));
}

// What was applied at the grant's now changed the acceptance filter: the broker granted as far as
// the old filter allowed, so the process stops at now and reports that.
TEST(VirtualTimeClient, AChangedFilterEndsALongGrantAtItsNow) {
  GrantedScheduler s;
  std::vector<std::string> log;
  Timer tpdo(s, [&] { log.push_back("tpdo at " + std::to_string(s.Now().time_since_epoch().count())); });
  VirtualTimeClient client(s, "quad-5#1", 1);
  FakePort port("p1", log, s);
  client.Connected(0, port, TimePoint(0ns));
  tpdo.StartAt(TimePoint(100ms));
  port.filter_changed = true;
  client.Granted(0, TimePoint(10ms), TimePoint(300ms));
  EXPECT_EQ(log, (std::vector<std::string>{"p1 apply at 10000000", "p1 reached 10000000 next 100000000"}));
  EXPECT_EQ(client.EarlyStops(), 1u);
  log.clear();
  client.Granted(0, TimePoint(10ms), TimePoint(10ms + 24us));
  EXPECT_EQ(log, (std::vector<std::string>{"p1 apply at 10000000", "p1 reached 10024000 next 100000000"}))
      << "a grant no longer than a frame's travel runs to its end";
}

// A timer changes the filter (a power supply falls asleep and wakes on any frame): the grant ends
// after that instant.
TEST(VirtualTimeClient, AFilterChangedByATimerEndsALongGrantAfterItsInstant) {
  GrantedScheduler s;
  std::vector<std::string> log;
  VirtualTimeClient client(s, "ps-9#1", 1);
  FakePort port("p1", log, s);
  Timer sleep(s, [&] { port.filter_changed = true; });
  Timer later(s, [&] { log.push_back("later"); });
  client.Connected(0, port, TimePoint(0ns));
  sleep.StartAt(TimePoint(40ms));
  later.StartAt(TimePoint(60ms));
  client.Granted(0, TimePoint(10ms), TimePoint(300ms));
  EXPECT_EQ(log, (std::vector<std::string>{"p1 apply at 10000000", "p1 reached 40000000 next 60000000"}));
}

// A timer confined to one identifier that arms one confined otherwise breaks its promise: counted.
TEST(VirtualTimeClient, AConfinedTimerThatArmsAnotherIsCounted) {
  GrantedScheduler s;
  Timer other(s, [] {});
  Timer tpdo(s, [&] { other.StartAfter(1ms); });
  tpdo.Confine(0x185);
  tpdo.StartAt(TimePoint(1ms));
  s.AdvanceTo(TimePoint(2ms));
  EXPECT_EQ(s.ConfinementBreaches(), 1u);
  EXPECT_EQ(s.RunningConfinement(), Timer::kUnconfined);
}

}  // namespace
}  // namespace canfleet
