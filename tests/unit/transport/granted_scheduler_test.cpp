// The third scheduler driver (clock/granted_scheduler.hpp, design decision 2): time granted from
// outside, standing still between grants.
#include "clock/granted_scheduler.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace canfleet {
namespace {

using namespace std::chrono_literals;

TimePoint At(Duration d) {
  return TimePoint(d);
}

// Each timer runs at its own deadline (Now() inside the callback), and time then stands at the
// grant's end; a timer armed at the current time by a callback runs in the same advance.
TEST(GrantedScheduler, RunsEachTimerAtItsDeadlineThenStandsAtTheGrant) {
  GrantedScheduler s;
  std::vector<Duration> seen;
  Timer second(s, [&] { seen.push_back(s.Now().time_since_epoch()); });
  Timer first(s, [&] {
    seen.push_back(s.Now().time_since_epoch());
    second.StartAfter(0ms);
  });
  first.StartAt(At(3ms));
  s.AdvanceTo(At(10ms));
  EXPECT_EQ(seen, (std::vector<Duration>{3ms, 3ms}));
  EXPECT_EQ(s.Now(), At(10ms));
  EXPECT_FALSE(s.NextDeadline());
}

// A timer due after the grant stays armed: it is the node's next deadline (TimeReached).
TEST(GrantedScheduler, ATimerAfterTheGrantIsTheNextDeadline) {
  GrantedScheduler s;
  int fired = 0;
  Timer t(s, [&] { ++fired; });
  t.StartAt(At(500ms));
  s.AdvanceTo(At(499ms));
  EXPECT_EQ(fired, 0);
  ASSERT_TRUE(s.NextDeadline());
  EXPECT_EQ(*s.NextDeadline(), At(500ms));
  s.AdvanceTo(At(500ms));  // a grant up to and including the deadline runs it
  EXPECT_EQ(fired, 1);
}

// Time never goes back: a grant in the past is now.
TEST(GrantedScheduler, AGrantInThePastLeavesTimeWhereItIs) {
  GrantedScheduler s;
  s.AdvanceTo(At(5ms));
  s.AdvanceTo(At(2ms));
  EXPECT_EQ(s.Now(), At(5ms));
}

}  // namespace
}  // namespace canfleet
