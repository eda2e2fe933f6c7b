#include "clock/asio_scheduler.hpp"

#include <gtest/gtest.h>

namespace canfleet {
namespace {

using namespace std::chrono_literals;

// The real-time driver is checked for ordering and for never firing early; no upper bound on
// lateness is asserted (a loaded CI machine may be slow).
TEST(AsioScheduler, FiresRealTimersInOrderAndNotEarly) {
  asio::io_context io;
  AsioScheduler s(io);
  std::vector<int> order;
  std::vector<TimePoint> when;
  Timer late(s, [&] {
    order.push_back(2);
    when.push_back(s.Now());
  });
  Timer early(s, [&] {
    order.push_back(1);
    when.push_back(s.Now());
  });
  auto start = s.Now();
  late.StartAfter(20ms);
  early.StartAfter(5ms);
  io.run();
  EXPECT_EQ(order, (std::vector<int>{1, 2}));
  EXPECT_GE(when[0] - start, 5ms);
  EXPECT_GE(when[1] - start, 20ms);
}

TEST(AsioScheduler, RearmingToAnEarlierDeadlineIsHonoured) {
  asio::io_context io;
  AsioScheduler s(io);
  bool fired = false;
  Timer t(s, [&] { fired = true; });
  t.StartAfter(10s);
  t.StartAfter(1ms);
  io.run_for(5s);
  EXPECT_TRUE(fired);
}

}  // namespace
}  // namespace canfleet
