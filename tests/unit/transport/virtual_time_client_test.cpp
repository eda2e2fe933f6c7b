// A node process's side of lock-step virtual time (bus/broker_client/virtual_time_client.hpp): what
// the broker sent is applied at the grant's time, timers run to the grant's end, and a process with
// two ports runs only once both are granted.
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
  void Reached(TimePoint time, std::optional<TimePoint> next) override {
    log_.push_back(name_ + " reached " + std::to_string(time.time_since_epoch().count()) +
                   (next ? " next " + std::to_string(next->time_since_epoch().count()) : " idle"));
  }
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

// A port that disconnects is no longer waited for.
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

// A node joining a running bus starts at the bus's time.
TEST(VirtualTimeClient, ANodeJoiningARunningBusStartsAtItsTime) {
  GrantedScheduler s;
  std::vector<std::string> log;
  VirtualTimeClient client(s, "quad#4", 1);
  FakePort a("a", log, s);
  client.Connected(0, a, TimePoint(3600s));
  EXPECT_EQ(s.Now(), TimePoint(3600s));
}

}  // namespace
}  // namespace canfleet
