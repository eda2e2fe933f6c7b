#include "clock/scheduler.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <string>

namespace canfleet {
namespace {

using namespace std::chrono_literals;

TEST(SimulatedScheduler, FiresTimersInDeadlineOrderEachAtItsOwnTime) {
  SimulatedScheduler s;
  std::vector<std::pair<std::string, Duration>> fired;
  Timer a(s, [&] { fired.emplace_back("a", s.Now().time_since_epoch()); });
  Timer b(s, [&] { fired.emplace_back("b", s.Now().time_since_epoch()); });
  Timer c(s, [&] { fired.emplace_back("c", s.Now().time_since_epoch()); });
  a.StartAfter(30ms);
  b.StartAfter(10ms);
  c.StartAfter(20ms);
  s.Advance(25ms);
  ASSERT_EQ(fired.size(), 2u);
  EXPECT_EQ(fired[0], std::make_pair(std::string("b"), Duration(10ms)));
  EXPECT_EQ(fired[1], std::make_pair(std::string("c"), Duration(20ms)));
  EXPECT_EQ(s.Now().time_since_epoch(), 25ms);
  s.Advance(5ms);
  EXPECT_EQ(fired.size(), 3u);
}

TEST(SimulatedScheduler, EqualDeadlinesFireInArmingOrder) {
  SimulatedScheduler s;
  std::string order;
  Timer x(s, [&] { order += 'x'; });
  Timer y(s, [&] { order += 'y'; });
  y.StartAfter(5ms);
  x.StartAfter(5ms);
  s.Advance(5ms);
  EXPECT_EQ(order, "yx");
}

TEST(SimulatedScheduler, PeriodicTimerRearmingItselfDoesNotDrift) {
  SimulatedScheduler s;
  int count = 0;
  Timer* self = nullptr;
  Timer periodic(s, [&] {
    ++count;
    self->StartAt(self->Deadline() + 100ms);
  });
  self = &periodic;
  periodic.StartAfter(100ms);
  s.Advance(1s);
  EXPECT_EQ(count, 10);
  EXPECT_EQ(periodic.Deadline().time_since_epoch(), 1100ms);
}

TEST(SimulatedScheduler, CancelRearmAndDestroyRemoveTimers) {
  SimulatedScheduler s;
  int fired = 0;
  Timer a(s, [&] { ++fired; });
  a.StartAfter(10ms);
  a.StartAfter(50ms);  // re-arm replaces the earlier deadline
  s.Advance(20ms);
  EXPECT_EQ(fired, 0);
  a.Cancel();
  s.Advance(100ms);
  EXPECT_EQ(fired, 0);
  {
    Timer b(s, [&] { ++fired; });
    b.StartAfter(1ms);
    EXPECT_EQ(s.ArmedCount(), 1u);
  }
  EXPECT_EQ(s.ArmedCount(), 0u);
  s.Advance(10ms);
  EXPECT_EQ(fired, 0);
}

TEST(SimulatedScheduler, ACallbackMayCancelALaterTimerDueInTheSameAdvance) {
  SimulatedScheduler s;
  bool late_fired = false;
  Timer late(s, [&] { late_fired = true; });
  Timer early(s, [&] { late.Cancel(); });
  early.StartAfter(1ms);
  late.StartAfter(2ms);
  s.Advance(10ms);
  EXPECT_FALSE(late_fired);
}

TEST(SimulatedScheduler, NextDeadlineReportsTheEarliestArmedTimer) {
  SimulatedScheduler s;
  EXPECT_FALSE(s.NextDeadline());
  Timer a(s, [] {}), b(s, [] {});
  a.StartAfter(7ms);
  b.StartAfter(3ms);
  EXPECT_EQ(s.NextDeadline()->time_since_epoch(), 3ms);
  b.Cancel();
  EXPECT_EQ(s.NextDeadline()->time_since_epoch(), 7ms);
  EXPECT_EQ(s.RunUntilIdle(1h).time_since_epoch(), 7ms);
}

// The heap must stay ordered under any mix of arm, re-arm and cancel.
TEST(SimulatedScheduler, RandomisedOperationsKeepDeadlineOrder) {
  SimulatedScheduler s;
  std::mt19937 rng(42);
  std::vector<TimePoint> fired_at;
  std::vector<std::unique_ptr<Timer>> timers;
  for (int i = 0; i < 200; ++i) {
    timers.push_back(std::make_unique<Timer>(s, [&] { fired_at.push_back(s.Now()); }));
  }
  for (int step = 0; step < 5000; ++step) {
    auto& t = *timers[rng() % timers.size()];
    switch (rng() % 3) {
      case 0:
      case 1:
        t.StartAfter(Duration(rng() % 1000000));
        break;
      case 2:
        t.Cancel();
        break;
    }
    if (step % 100 == 0) s.Advance(Duration(rng() % 200000));
  }
  s.RunUntilIdle(1h);
  EXPECT_TRUE(std::is_sorted(fired_at.begin(), fired_at.end()));
  EXPECT_EQ(s.ArmedCount(), 0u);
}

}  // namespace
}  // namespace canfleet

namespace canfleet {
namespace {

// An object holding a timer may be destroyed after the scheduler it was made with (the socketcand
// session's shutdown did): an unarmed timer's Cancel, and so its destructor, must not touch the
// scheduler (ASan in the sanitizer job sees a use after free if it does).
TEST(SimulatedScheduler, AnUnarmedTimerMayOutliveItsScheduler) {
  auto scheduler = std::make_unique<SimulatedScheduler>();
  auto timer = std::make_unique<Timer>(*scheduler, [] {});
  timer->StartAfter(std::chrono::milliseconds(5));
  scheduler->Advance(std::chrono::milliseconds(5));  // fired: no longer armed
  scheduler.reset();
  timer->Cancel();
  timer.reset();
  SUCCEED();
}

}  // namespace
}  // namespace canfleet
