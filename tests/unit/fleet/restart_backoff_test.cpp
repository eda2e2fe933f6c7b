// The restart delay of a crashed node process (orchestrator/fleet/restart_backoff.hpp; issue 32:
// "restart backoff resets after a stated stable period"), on simulated durations.
#include "orchestrator/fleet/restart_backoff.hpp"

#include <gtest/gtest.h>

namespace canfleet::fleet {
namespace {

using namespace std::chrono_literals;

TEST(RestartBackoff, DoublesWhileTheProcessKeepsCrashingUpToTheCeiling) {
  RestartBackoff backoff(500ms);
  EXPECT_EQ(backoff.After(1s), 500ms);
  EXPECT_EQ(backoff.After(1s), 1000ms);
  EXPECT_EQ(backoff.After(2s), 2000ms);
  EXPECT_EQ(backoff.After(2s), 4000ms);
  EXPECT_EQ(backoff.After(2s), 8000ms);
  EXPECT_EQ(backoff.After(2s), RestartBackoff::kMaxDelay);
  EXPECT_EQ(backoff.After(59s), RestartBackoff::kMaxDelay) << "just short of stable";
}

TEST(RestartBackoff, AStableRunStartsAFreshEpisode) {
  RestartBackoff backoff(200ms);
  for (int i = 0; i < 8; ++i)
    backoff.After(100ms);
  EXPECT_EQ(backoff.After(RestartBackoff::kStablePeriod), 200ms);
  EXPECT_EQ(backoff.After(100ms), 400ms);
  EXPECT_EQ(backoff.After(std::chrono::hours(3)), 200ms);
}

TEST(RestartBackoff, AZeroFirstDelayStaysZero) {
  RestartBackoff backoff(0ms);
  EXPECT_EQ(backoff.After(0ms), 0ms);
  EXPECT_EQ(backoff.After(0ms), 0ms);
}

}  // namespace
}  // namespace canfleet::fleet
