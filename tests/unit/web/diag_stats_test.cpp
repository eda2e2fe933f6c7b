// DiagStats: CANopen-Diag-like statistics from frames with their bus times (web/diag_stats.hpp).
#include "web/diag_stats.hpp"

#include <gtest/gtest.h>

namespace canfleet::web {
namespace {

CanFrame Data(std::uint32_t id, std::initializer_list<std::uint8_t> bytes) {
  CanFrame f;
  f.id = id;
  f.dlc = static_cast<std::uint8_t>(bytes.size());
  std::size_t i = 0;
  for (const auto b : bytes)
    f.data[i++] = b;
  return f;
}

constexpr std::int64_t kMs = 1'000'000;

// Heartbeat 705h every 100 ms with one late by 4 ms (CiA 301 §7.2.8.3.2.2): min, max, jitter.
TEST(DiagStats, HeartbeatPeriodMinMaxAndJitter) {
  DiagStats stats;
  const std::int64_t times[] = {0, 100, 200, 304, 400, 500};
  for (const auto t : times)
    stats.Frame("can0", Data(0x705, {0x05}), t * kMs);
  const NodeDiag* d = stats.Find("can0", 5);
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->heartbeats, 6u);
  EXPECT_EQ(d->hb_min_ns, 96 * kMs);
  EXPECT_EQ(d->hb_max_ns, 104 * kMs);
  // Periods 100, 100, 104, 96, 100: mean 100, sample standard deviation sqrt(32/4) = 2.83 ms.
  EXPECT_NEAR(d->JitterNs() / 1e6, 2.828, 0.001);
}

// A boot-up (700h+ID, 00h) counts and starts a new life: no period across it.
TEST(DiagStats, ABootUpCountsAndRestartsThePeriods) {
  DiagStats stats;
  stats.Frame("can0", Data(0x706, {0x05}), 0);
  stats.Frame("can0", Data(0x706, {0x00}), 50 * kMs);
  stats.Frame("can0", Data(0x706, {0x7F}), 60 * kMs);
  stats.Frame("can0", Data(0x706, {0x7F}), 160 * kMs);
  const NodeDiag* d = stats.Find("can0", 6);
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->bootups, 1u);
  EXPECT_EQ(d->hb_min_ns, 100 * kMs);
  EXPECT_EQ(d->hb_max_ns, 100 * kMs);
}

// SDO (CiA 301 §7.2.4): the time from a request 600h+ID to the answer 580h+ID; aborts counted; an
// answer to a request made before the monitor watched is not timed.
TEST(DiagStats, SdoResponseTimesAndAborts) {
  DiagStats stats;
  stats.Frame("can0", Data(0x585, {0x4B, 0x17, 0x10, 0x00, 0x64, 0x00, 0, 0}), 1 * kMs);  // no request seen
  stats.Frame("can0", Data(0x605, {0x40, 0x17, 0x10, 0x00, 0, 0, 0, 0}), 10 * kMs);
  stats.Frame("can0", Data(0x585, {0x4B, 0x17, 0x10, 0x00, 0x64, 0x00, 0, 0}), 11 * kMs);
  stats.Frame("can0", Data(0x605, {0x40, 0x00, 0x20, 0x00, 0, 0, 0, 0}), 20 * kMs);
  stats.Frame("can0", Data(0x585, {0x80, 0x00, 0x20, 0x00, 0x00, 0x00, 0x02, 0x06}), 23 * kMs);
  const NodeDiag* d = stats.Find("can0", 5);
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->sdo_responses, 2u);
  EXPECT_EQ(d->sdo_aborts, 1u);
  EXPECT_EQ(d->sdo_min_ns, 1 * kMs);
  EXPECT_EQ(d->sdo_max_ns, 3 * kMs);
  EXPECT_EQ(DiagStats::Json(*d),
            "{\"hb_min_ms\":null,\"hb_max_ms\":null,\"hb_jitter_ms\":null,\"heartbeats\":0,\"bootups\":0,"
            "\"sdo_min_ms\":1.000,\"sdo_max_ms\":3.000,\"sdo_last_ms\":3.000,\"sdo_responses\":2,"
            "\"sdo_aborts\":1,\"emcys\":0}");
}

TEST(DiagStats, EmcysCountAndOtherFramesAreIgnored) {
  DiagStats stats;
  stats.Frame("can1", Data(0x086, {0x30, 0x81, 0x01, 0x05, 0x08, 0, 0, 0}), 0);
  stats.Frame("can1", Data(0x186, {1, 2}), 0);  // a TPDO
  CanFrame extended = Data(0x705, {0x05});
  extended.flags = CanFrame::kExtended;
  stats.Frame("can1", extended, 0);
  stats.Frame("can1", Data(0x000, {0x01, 0x00}), 0);  // NMT
  ASSERT_NE(stats.Find("can1", 6), nullptr);
  EXPECT_EQ(stats.Find("can1", 6)->emcys, 1u);
  EXPECT_EQ(stats.Find("can1", 5), nullptr);
  EXPECT_EQ(stats.Find("can0", 6), nullptr) << "by bus";
}

}  // namespace
}  // namespace canfleet::web
