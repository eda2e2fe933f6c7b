// Sleeping periodic timers (design decision 10, "time is events"): a timer put to sleep costs no
// wake-up, and a woken one fires at the instant, and in the order among timers due at that
// instant, it would have had if it had never slept.
#include <gtest/gtest.h>

#include <asio/io_context.hpp>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "clock/asio_scheduler.hpp"
#include "clock/scheduler.hpp"

namespace canfleet {
namespace {

using namespace std::chrono_literals;

std::int64_t Ms(TimePoint t) {
  return std::chrono::duration_cast<std::chrono::milliseconds>(t.time_since_epoch()).count();
}

TEST(SleepingTimer, CostsNoWakeUpAndWakesOnItsGrid) {
  SimulatedScheduler s;
  std::vector<std::int64_t> fired_at;
  Timer* self = nullptr;
  Timer tick(s, [&] {
    self->StartAt(self->Deadline() + 10ms);
    fired_at.push_back(Ms(s.Now()));
  });
  self = &tick;
  tick.StartAfter(10ms);
  s.Advance(10ms);
  tick.Sleep(10ms);  // armed for 20 ms: asleep from there on
  EXPECT_TRUE(tick.Asleep());
  EXPECT_FALSE(tick.Armed());
  EXPECT_EQ(s.NextDeadline(), std::nullopt);
  EXPECT_EQ(s.ArmedCount(), 0u);
  EXPECT_EQ(s.SleepingCount(), 1u);
  const auto fired_before = s.FiredCount();
  s.Advance(1s + 3ms);  // t = 1013 ms
  EXPECT_EQ(s.FiredCount(), fired_before);
  tick.Wake();
  EXPECT_EQ(Ms(*s.NextDeadline()), 1020);  // the grid of 10 ms, not 1013 + 10
  s.Advance(20ms);
  EXPECT_EQ(fired_at, (std::vector<std::int64_t>{10, 1020, 1030}));
}

// A timer armed after the periodic timer re-armed itself (at 6 ms, for 7 ms) comes after it at 7 ms;
// one armed before comes first. A woken sleeper keeps that order: X (armed at 5.5 ms), P, Y (armed
// at 6.5 ms), exactly as if P had run every millisecond.
TEST(SleepingTimer, WokenTimerKeepsItsPlaceAmongTimersDueAtTheSameInstant) {
  SimulatedScheduler s;
  std::string order;
  Timer* p_self = nullptr;
  Timer p(s, [&] {
    p_self->StartAt(p_self->Deadline() + 1ms);
    order += 'P';
  });
  p_self = &p;
  Timer x(s, [&] {
    order += 'X';
    p.Wake();
  });
  Timer y(s, [&] {
    order += 'Y';
    p.Wake();
  });
  p.StartAfter(1ms);
  s.Advance(5ms);
  p.Sleep(1ms);
  order.clear();
  s.Advance(500us);
  x.StartAt(TimePoint{7ms});
  s.Advance(1ms);
  y.StartAt(TimePoint{7ms});
  s.Advance(500us);  // t = 7 ms
  EXPECT_EQ(order, "XPY");
}

// A small world that exercises every order question: periodic activities on a 1 ms and a 10 ms
// grid (they re-arm first, as devices::PeriodicTick does; two share the 1 ms grid, so sleepers tie
// with each other too), each with work for a few ticks after it is given some, and events at random
// instants, many on the grids, armed from the periodic callbacks, from events and from outside
// between advances. With `sleep`, a periodic activity sleeps when it has no work and whoever gives
// it work wakes it.
struct WorldRun {
  std::vector<std::string> log;
  std::uint64_t fired = 0;
};

WorldRun RunWorld(bool sleep, unsigned seed) {
  SimulatedScheduler s;
  std::mt19937 rng(seed);
  WorldRun run;
  const auto note = [&](const std::string& what) {
    run.log.push_back(what + "@" + std::to_string(s.Now().time_since_epoch().count()));
  };
  const auto delay = [&] {
    static constexpr Duration kDelays[] = {0ms, 250us, 500us, 1ms, 1ms, 2ms, 1500us, 3ms, 10ms, 20ms};
    return kDelays[rng() % std::size(kDelays)];
  };
  struct Periodic {
    std::string name;
    Duration period;
    int work = 0;
    std::unique_ptr<Timer> timer;
  };
  std::vector<Periodic> periodics(3);
  periodics[0] = {"P", 1ms, 0, nullptr};
  periodics[1] = {"Q", 10ms, 0, nullptr};
  periodics[2] = {"R", 1ms, 0, nullptr};
  std::vector<std::unique_ptr<Timer>> events;
  const auto give_work = [&] {
    Periodic& p = periodics[rng() % periodics.size()];
    p.work = 1 + static_cast<int>(rng() % 4);
    if (sleep) p.timer->Wake();
  };
  for (Periodic& p : periodics) {
    p.timer = std::make_unique<Timer>(s, [&] {
      p.timer->StartAt(p.timer->Deadline() + p.period);
      if (p.work > 0) {
        note(p.name);
        --p.work;
        if (rng() % 3 == 0) events[rng() % events.size()]->StartAfter(delay());
        if (rng() % 5 == 0) give_work();
      }
      if (sleep && p.work == 0) p.timer->Sleep(p.period);
    });
    p.timer->StartAfter(p.period);
  }
  for (int i = 0; i < 6; ++i) {
    events.push_back(std::make_unique<Timer>(s, [&, i] {
      note("E" + std::to_string(i));
      if (rng() % 2 == 0) give_work();
      if (rng() % 3 != 0) events[rng() % events.size()]->StartAfter(delay());
    }));
  }
  for (auto& e : events)
    e->StartAfter(delay());
  for (int step = 0; step < 3000; ++step) {
    s.Advance(rng() % 2 == 0 ? delay() : Duration(rng() % 30000000));
    switch (rng() % 4) {
      case 0:
        give_work();
        break;
      case 1:
        events[rng() % events.size()]->StartAfter(delay());
        break;
      default:
        break;
    }
  }
  run.fired = s.FiredCount();
  return run;
}

TEST(SleepingTimer, AWorldWithSleepingTicksRunsExactlyAsWithFixedTicks) {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const WorldRun fixed = RunWorld(false, seed);
    const WorldRun on_demand = RunWorld(true, seed);
    ASSERT_EQ(fixed.log, on_demand.log) << "seed " << seed;
    EXPECT_GT(fixed.log.size(), 1000u);
    EXPECT_LT(on_demand.fired * 2, fixed.fired) << "seed " << seed;
  }
}

TEST(SleepingTimer, CancelAndRearmEndTheSleep) {
  SimulatedScheduler s;
  int fired = 0;
  Timer t(s, [&] { ++fired; });
  t.StartAfter(1ms);
  t.Sleep(1ms);
  t.Cancel();
  EXPECT_FALSE(t.Asleep());
  EXPECT_EQ(s.SleepingCount(), 0u);
  t.StartAfter(1ms);
  t.Sleep(1ms);
  t.StartAfter(5ms);  // armed again: awake, at its new deadline
  EXPECT_FALSE(t.Asleep());
  s.Advance(5ms);
  EXPECT_EQ(fired, 1);
  t.Sleep(1ms);  // not armed: nothing to put to sleep
  EXPECT_FALSE(t.Asleep());
  {
    Timer gone(s, [] {});
    gone.StartAfter(1ms);
    gone.Sleep(1ms);
  }
  EXPECT_EQ(s.SleepingCount(), 0u);
}

// In real time the event loop does not wake for a sleeping timer; a wake-up from another timer
// puts it back on its grid.
TEST(SleepingTimer, RealTimeDriverWaitsOnlyForAwakeTimers) {
  asio::io_context io;
  AsioScheduler s(io);
  const TimePoint start = s.Now();
  int ticks = 0;
  std::vector<TimePoint> tick_at;
  Timer* self = nullptr;
  Timer tick(s, [&] {
    self->StartAt(self->Deadline() + 1ms);
    ++ticks;
    tick_at.push_back(s.Now());
    if (ticks == 3) {  // a late loop may find several due at once: stop the tick itself
      self->Cancel();
      io.stop();
    }
  });
  self = &tick;
  tick.StartAt(start + 1ms);
  tick.Sleep(1ms);
  Timer waker(s, [&] { tick.Wake(); });
  waker.StartAt(start + 30ms + 500us);
  io.run_for(5s);
  ASSERT_EQ(ticks, 3);
  EXPECT_GE(tick_at[0] - start, 31ms);  // the first instant of the grid after the wake-up
  EXPECT_EQ(tick.Deadline() - start, 34ms);
}

}  // namespace
}  // namespace canfleet
