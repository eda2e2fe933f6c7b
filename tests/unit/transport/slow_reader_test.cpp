// A client that cannot keep up (orchestrator/transport/slow_reader.hpp; issue 32): dropped items
// are counted, and once the episode has lasted the limit the client is to be disconnected. On
// simulated time points.
#include "orchestrator/transport/slow_reader.hpp"

#include <gtest/gtest.h>

namespace canfleet::transport {
namespace {

using namespace std::chrono_literals;

TEST(SlowReader, DisconnectOnlyOnceTheEpisodeHasLastedTheLimit) {
  SlowReader slow(10s);
  const SlowReader::Clock::time_point t0{};
  EXPECT_FALSE(slow.Dropping());
  EXPECT_FALSE(slow.Dropped(5, t0));
  EXPECT_TRUE(slow.Dropping());
  EXPECT_FALSE(slow.Dropped(5, t0 + 9999ms));
  EXPECT_TRUE(slow.Dropped(1, t0 + 10s));
  EXPECT_EQ(slow.dropped(), 11u);
  EXPECT_EQ(slow.Reason("frames"), "not reading: 11 frames dropped over 10 s");
}

TEST(SlowReader, CatchingUpEndsTheEpisode) {
  SlowReader slow(10s);
  const SlowReader::Clock::time_point t0{};
  slow.Dropped(3, t0);
  EXPECT_EQ(slow.CaughtUp(), 3u);
  EXPECT_FALSE(slow.Dropping());
  EXPECT_EQ(slow.CaughtUp(), 0u);
  // A new episode counts from its own first drop.
  EXPECT_FALSE(slow.Dropped(1, t0 + 60s));
  EXPECT_FALSE(slow.Dropped(1, t0 + 69s));
  EXPECT_TRUE(slow.Dropped(1, t0 + 70s));
}

}  // namespace
}  // namespace canfleet::transport
