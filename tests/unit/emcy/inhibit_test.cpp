// Inhibit time EMCY 1015h (CiA 301 v4.2 §7.5.2.18, multiples of 100 µs): consecutive EMCY frames
// are at least that far apart; frames raised meanwhile wait and go out when it has passed.
#include "tests/unit/emcy/emcy_fixture.hpp"

namespace canfleet::canopen {
namespace {

// Three events at once with a 1 ms inhibit time: at 0, 1 and 2 ms. A fourth at 2.5 ms waits for
// 3 ms; one after the inhibit time goes out at once. Each waiting frame keeps the error register
// of its event.
TEST_F(EmcyTest, InhibitTimeSpacesFramesAndQueuesTheRest) {
  auto& emcy = Start();
  ASSERT_EQ(WriteU16(0x1015, 10), SdoAbort::kNone);  // 10 × 100 µs
  emcy.Raise(Error(0x2320, 0x0401, kErrorRegisterCurrent));
  emcy.Clear(0x2320, 0x0401);
  emcy.Raise(Error(0x3300, 0x0102, kErrorRegisterVoltage));
  EXPECT_EQ(timed, (Timed{{0ms, "085#2023030000000000"}}));
  scheduler.Advance(2500us);
  emcy.Raise(Error(0x4210, 0x0001, kErrorRegisterTemperature));
  scheduler.Advance(7500us);
  emcy.Raise(Error(0x5000, 0x0001));
  EXPECT_EQ(timed, (Timed{{0ms, "085#2023030000000000"},
                          {1ms, "085#0000000000000000"},
                          {2ms, "085#0033050000000000"},
                          {3ms, "085#10420D0000000000"},
                          {10ms, "085#00500D0000000000"}}));
}

// Inhibit time 0 (the default): no spacing.
TEST_F(EmcyTest, NoInhibitTimeSendsEveryFrameAtOnce) {
  auto& emcy = Start();
  emcy.Raise(Error(0x2320, 0x0401));
  emcy.Raise(Error(0x2320, 0x0402));
  EXPECT_EQ(timed, (Timed{{0ms, "085#2023010000000000"}, {0ms, "085#2023010000000000"}}));
  EXPECT_EQ(scheduler.ArmedCount(), 0u);
}

// At most kQueueCapacity frames wait; when full the oldest waiting one is dropped so the latest
// state gets out, and Overruns() counts it.
TEST_F(EmcyTest, FullInhibitQueueDropsTheOldestWaitingFrame) {
  auto& emcy = Start({}, 20);
  ASSERT_EQ(WriteU16(0x1015, 10000), SdoAbort::kNone);  // 1 s
  for (std::uint8_t i = 1; i <= Emcy::kQueueCapacity + 2; ++i)
    emcy.Raise(Error(0xF001, i, 0x01, {i, 0, 0, 0, 0}));
  EXPECT_EQ(emcy.Overruns(), 1u);
  scheduler.RunUntilIdle(60s);
  ASSERT_EQ(timed.size(), Emcy::kQueueCapacity + 1);
  EXPECT_EQ(timed[0], std::make_pair(Duration(0s), std::string("085#01F0010100000000")));
  EXPECT_EQ(timed[1], std::make_pair(Duration(1s), std::string("085#01F0010300000000")));  // 2 was dropped
  EXPECT_EQ(timed[16], std::make_pair(Duration(16s), std::string("085#01F0011200000000")));
}

// A new inhibit time applies to the frame already waiting: it goes out 3 ms after the last one.
TEST_F(EmcyTest, ChangingTheInhibitTimeMovesTheWaitingFrame) {
  auto& emcy = Start();
  ASSERT_EQ(WriteU16(0x1015, 100), SdoAbort::kNone);  // 10 ms
  emcy.Raise(Error(0x2320, 0x0401));
  emcy.Raise(Error(0x2320, 0x0402));
  scheduler.Advance(2ms);
  ASSERT_EQ(WriteU16(0x1015, 30), SdoAbort::kNone);  // 3 ms
  scheduler.Advance(8ms);
  EXPECT_EQ(timed, (Timed{{0ms, "085#2023010000000000"}, {3ms, "085#2023010000000000"}}));
}

// Stopped (table 51) drops the waiting frames: they are not sent after the node returns.
TEST_F(EmcyTest, EnteringStoppedDropsWaitingFrames) {
  auto& emcy = Start();
  ASSERT_EQ(WriteU16(0x1015, 10), SdoAbort::kNone);  // 1 ms
  emcy.Raise(Error(0x2320, 0x0401));
  emcy.Raise(Error(0x2320, 0x0402));
  scheduler.Advance(500us);
  emcy.SetNmtState(NmtState::kStopped);
  scheduler.Advance(200us);
  emcy.SetNmtState(NmtState::kPreOperational);  // before the waiting frame was due (1 ms)
  scheduler.Advance(5300us);
  emcy.Raise(Error(0x2320, 0x0403));
  EXPECT_EQ(timed, (Timed{{0ms, "085#2023010000000000"}, {6ms, "085#2023010000000000"}}));
  EXPECT_EQ(emcy.ActiveCount(), 3u);
}

// Invalidating 1014h drops the waiting frames too.
TEST_F(EmcyTest, InvalidatingTheCobIdDropsWaitingFrames) {
  auto& emcy = Start();
  ASSERT_EQ(WriteU16(0x1015, 10), SdoAbort::kNone);
  emcy.Raise(Error(0x2320, 0x0401));
  emcy.Raise(Error(0x2320, 0x0402));
  ASSERT_EQ(WriteU32(0x1014, 0x80000085), SdoAbort::kNone);
  ASSERT_EQ(WriteU32(0x1014, 0x00000085), SdoAbort::kNone);
  scheduler.Advance(5ms);
  EXPECT_EQ(timed, (Timed{{0ms, "085#2023010000000000"}}));
}

// Reset node forgets the inhibit state as well: the next frame goes out at once.
TEST_F(EmcyTest, ClearAllDropsWaitingFramesAndTheInhibitState) {
  auto& emcy = Start();
  ASSERT_EQ(WriteU16(0x1015, 10000), SdoAbort::kNone);
  emcy.Raise(Error(0x2320, 0x0401));
  emcy.Raise(Error(0x2320, 0x0402));
  emcy.ClearAll();
  EXPECT_EQ(scheduler.ArmedCount(), 0u);
  scheduler.Advance(1ms);
  emcy.Raise(Error(0x2320, 0x0403));
  EXPECT_EQ(timed, (Timed{{0ms, "085#2023010000000000"}, {1ms, "085#2023010000000000"}}));
}

}  // namespace
}  // namespace canfleet::canopen
