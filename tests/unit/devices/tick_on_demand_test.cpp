// PeriodicTick on demand (periodic_tick.hpp, design decision 10): it sleeps after a tick that
// found nothing to do and, woken, runs at the next instant of its original grid.
#include <gtest/gtest.h>

#include <vector>

#include "node/devices/periodic_tick.hpp"

namespace canfleet::devices {
namespace {

using namespace std::chrono_literals;

std::int64_t Ms(TimePoint t) {
  return std::chrono::duration_cast<std::chrono::milliseconds>(t.time_since_epoch()).count();
}

TEST(TickOnDemandTest, SleepsWhenIdleAndResumesOnItsGrid) {
  SimulatedScheduler scheduler;
  std::vector<std::int64_t> at;
  int work = 2;  // two ticks with something to do
  PeriodicTick tick(
      scheduler, 10ms, [&] { at.push_back(Ms(scheduler.Now())); }, [&] { return --work <= 0; });
  tick.Start();
  scheduler.Advance(1s);
  EXPECT_EQ(at, (std::vector<std::int64_t>{10, 20}));
  EXPECT_TRUE(tick.Asleep());
  EXPECT_TRUE(tick.Running());
  EXPECT_EQ(scheduler.NextDeadline(), std::nullopt);
  scheduler.Advance(3ms);  // t = 1003 ms
  work = 1;
  tick.Wake();
  scheduler.Advance(1s);
  EXPECT_EQ(at, (std::vector<std::int64_t>{10, 20, 1010}));
  EXPECT_EQ(tick.Count(), 3u);
  tick.Stop();
  EXPECT_FALSE(tick.Running());
}

// A Wake() during the tick (the tick itself wrote an object or moved an output) means its inputs
// may have changed: one more tick before it may sleep.
TEST(TickOnDemandTest, AWakeDuringTheTickKeepsItRunningOneMoreTick) {
  SimulatedScheduler scheduler;
  int ticks = 0;
  PeriodicTick* self = nullptr;
  PeriodicTick tick(
      scheduler, 1ms,
      [&] {
        if (++ticks == 1) self->Wake();
      },
      [] { return true; });
  self = &tick;
  tick.Start();
  scheduler.Advance(10ms);
  EXPECT_EQ(ticks, 2);
  EXPECT_TRUE(tick.Asleep());
}

TEST(TickOnDemandTest, WithoutAnIdleTestTheTickNeverSleeps) {
  SimulatedScheduler scheduler;
  PeriodicTick tick(scheduler, 1ms, [] {});
  tick.Start();
  scheduler.Advance(100ms);
  EXPECT_EQ(tick.Count(), 100u);
  EXPECT_FALSE(tick.Asleep());
}

}  // namespace
}  // namespace canfleet::devices
