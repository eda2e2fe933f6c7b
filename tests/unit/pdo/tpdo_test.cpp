// TPDO transmission: CiA 301 v4.2 §7.2.2 (PDO services and transmission modes) and §7.5.2.37
// (1800h+: transmission type, inhibit time, event timer, SYNC start value); facts §4.
#include "tests/unit/pdo/pdo_fixture.hpp"

namespace canfleet::canopen::test_pdo {
namespace {

// Type 255 (event-driven, profile): a change of a mapped object sends the TPDO with the current
// values, packed in mapping order, little-endian.
TEST_F(PdoTest, Type255SendsWhenAMappedObjectChanges) {
  Start();
  Tpdo(1, {.entries = {0x60000108, 0x71000110}, .type = 255});
  Operational();
  Set(0x6000, 1, 0x12);
  Set(0x7100, 1, 0x3456);
  pdo->NotifyChanged(*di);
  pdo->NotifyChanged(*od.Find(0x7100, 2));  // not mapped: no event
  pdo->NotifyChanged(*od.Find(0x7100, 1));
  EXPECT_EQ(master.Take(), (Frames{"185#125634", "185#125634"}));
  EXPECT_EQ(pdo->Counters().tpdo_sent, 2u);
}

// Type 254 with an event timer (the manuals' 100 ms TPDOs): the timer starts on entering
// operational, sends when it expires and restarts with every transmission, event-caused or not.
TEST_F(PdoTest, Type254EventTimerRestartsWithEachTransmission) {
  Start();
  Tpdo(1, {.entries = {0x60000108}, .type = 254, .event_timer_ms = 100});
  scheduler.Advance(1s);
  EXPECT_TRUE(recorder.Take().empty());  // pre-operational: no timer
  Operational();                         // t = 1000 ms
  scheduler.Advance(99ms);
  EXPECT_TRUE(recorder.Take().empty());
  scheduler.Advance(51ms);
  Set(0x6000, 1, 7);
  pdo->NotifyChanged(*di);  // t = 1150 ms
  scheduler.Advance(200ms);
  EXPECT_EQ(recorder.Take(), (Frames{"1100ms 185#00", "1150ms 185#07", "1250ms 185#07", "1350ms 185#07"}));
}

// Inhibit time (sub3, 100 µs units): an event within it is delayed to its end, never dropped;
// events meanwhile give one frame with the data of its sending time.
TEST_F(PdoTest, InhibitTimeDelaysEventsAndNeverDropsThem) {
  Start();
  Tpdo(1, {.entries = {0x60000108}, .type = 255, .inhibit_100us = 100});  // 10 ms
  Operational();
  Set(0x6000, 1, 1);
  pdo->NotifyChanged(*di);
  scheduler.Advance(2ms);
  Set(0x6000, 1, 2);
  pdo->NotifyChanged(*di);
  scheduler.Advance(3ms);
  Set(0x6000, 1, 3);
  pdo->NotifyChanged(*di);
  scheduler.Advance(4999us);
  EXPECT_EQ(recorder.Take(), (Frames{"0ms 185#01"}));
  scheduler.Advance(1us);
  EXPECT_EQ(recorder.Take(), (Frames{"10ms 185#03"}));
  scheduler.Advance(20ms);
  pdo->NotifyChanged(*di);  // 30 ms: inhibit long over
  scheduler.Advance(1ms);
  pdo->NotifyChanged(*di);  // 31 ms: until 40 ms
  scheduler.Advance(20ms);
  EXPECT_EQ(recorder.Take(), (Frames{"30ms 185#03", "40ms 185#03"}));
}

// Event timer shorter than the inhibit time: each expiry is held to the end of the inhibit time,
// so the TPDO runs at the inhibit period; an application event meanwhile adds no extra frame.
TEST_F(PdoTest, EventTimerShorterThanInhibitTime) {
  Start();
  Tpdo(1, {.entries = {0x60000108}, .type = 254, .event_timer_ms = 20, .inhibit_100us = 300});
  Operational();
  scheduler.Advance(115ms);
  pdo->NotifyChanged(*di);  // 115 ms: inhibited until 140 ms
  scheduler.Advance(25ms);  // the event timer also expires at 130 ms
  EXPECT_EQ(recorder.Take(),
            (Frames{"20ms 185#00", "50ms 185#00", "80ms 185#00", "110ms 185#00", "140ms 185#00"}));
  scheduler.Advance(30ms);  // the expiry at 160 ms waits for the inhibit time to end at 170 ms
  EXPECT_EQ(recorder.Take(), (Frames{"170ms 185#00"}));
}

// Type 0 (synchronous acyclic): an event makes the TPDO go out at the next SYNC, with the data
// of that SYNC; no event, no frame.
TEST_F(PdoTest, Type0SendsAtTheSyncAfterAnEvent) {
  Start();
  Tpdo(1, {.entries = {0x60000108}, .type = 0});
  Operational();
  pdo->OnSync(0);
  EXPECT_EQ(master.Count(), 0u);
  Set(0x6000, 1, 1);
  pdo->NotifyChanged(*di);
  Set(0x6000, 1, 2);
  pdo->NotifyChanged(*di);
  EXPECT_EQ(master.Count(), 0u);
  pdo->OnSync(0);
  pdo->OnSync(0);
  pdo->RequestTpdo(1);
  pdo->OnSync(0);
  EXPECT_EQ(master.Take(), (Frames{"185#02", "185#02"}));
}

// Types 1–240: sent at every n-th SYNC, the n-th SYNC after the TPDO became active being the first.
TEST_F(PdoTest, CyclicSyncTypesSendEveryNthSync) {
  Start();
  Tpdo(1, {.entries = {0x60000108}, .type = 1});
  Tpdo(2, {.entries = {0x60000108}, .type = 3});
  Operational();
  pdo->NotifyChanged(*di);  // events do not trigger synchronous types
  std::vector<std::string> per_sync;
  for (int i = 1; i <= 7; ++i) {
    pdo->OnSync(0);
    std::string ids;
    for (const auto& frame : master.Take())
      ids += frame.substr(0, 3) + " ";
    per_sync.push_back(ids);
  }
  EXPECT_EQ(per_sync, (Frames{"185 ", "185 ", "185 285 ", "185 ", "185 ", "185 285 ", "185 "}));
}

// Sub6 SYNC start value (facts §4; CANopenNode CO_TPDO_process): the first transmission is at the
// SYNC whose counter equals it, then every n-th SYNC.
TEST_F(PdoTest, SyncStartValueSelectsTheFirstSync) {
  Start();
  Tpdo(1, {.entries = {0x60000108}, .type = 2, .sync_start = 3});
  Operational();
  for (std::uint8_t counter = 1; counter <= 8; ++counter) {
    Set(0x6000, 1, counter);
    pdo->OnSync(counter);
  }
  EXPECT_EQ(master.Take(), (Frames{"185#03", "185#05", "185#07"}));
}

// Without a counter in the SYNC (1019h = 0) the start value cannot match and is ignored.
TEST_F(PdoTest, SyncStartValueIsIgnoredWithoutSyncCounter) {
  Start();
  Tpdo(1, {.entries = {0x60000108}, .type = 2, .sync_start = 3});
  Operational();
  for (std::uint8_t i = 1; i <= 5; ++i) {
    Set(0x6000, 1, i);
    pdo->OnSync(0);
  }
  EXPECT_EQ(master.Take(), (Frames{"185#02", "185#04"}));
}

// Type 252 (synchronous RTR-only): sampled at each SYNC, sent only on RTR, with the sample.
TEST_F(PdoTest, Type252AnswersRtrWithTheDataOfTheLastSync) {
  Start();
  Tpdo(1, {.entries = {0x60000108}, .type = 252, .cob_id = 0x00000185});
  Operational();
  master.Send("185#R1");  // no SYNC yet: nothing sampled
  Set(0x6000, 1, 1);
  pdo->OnSync(0);
  EXPECT_EQ(master.Count(), 0u);
  Set(0x6000, 1, 2);
  master.Send("185#R1");
  master.Send("185#R");
  pdo->OnSync(0);
  master.Send("185#R1");
  EXPECT_EQ(master.Take(), (Frames{"185#01", "185#01", "185#02"}));
  EXPECT_EQ(consumed, (std::vector<bool>{true, true, true, true}));
}

// Type 253 (event RTR-only): an RTR gets the current data; events and SYNC do not send it.
TEST_F(PdoTest, Type253AnswersRtrWithCurrentData) {
  Start();
  Tpdo(1, {.entries = {0x60000108, 0x71000110}, .type = 253, .cob_id = 0x00000185});
  Operational();
  Set(0x6000, 1, 7);
  Set(0x7100, 1, -1);
  pdo->NotifyChanged(*di);
  pdo->OnSync(0);
  master.Send("185#R3");
  master.Send("186#R3");  // not ours
  EXPECT_EQ(master.Take(), (Frames{"185#07FFFF"}));
  EXPECT_EQ(consumed, (std::vector<bool>{true, false}));
}

// COB-ID bit 30 set: no RTR; an RTR on the TPDO's identifier is taken but not answered. Event
// types do not answer RTRs even when allowed (only 252/253 are RTR-triggered here).
TEST_F(PdoTest, RtrIsNotAnsweredUnlessTheTypeIsRtrOnlyAndRtrIsAllowed) {
  Start();
  Tpdo(1, {.entries = {0x60000108}, .type = 255});
  Tpdo(2, {.entries = {0x60000108}, .type = 255, .cob_id = 0x00000285});
  Operational();
  master.Send("185#R1");
  master.Send("285#R1");
  EXPECT_EQ(master.Count(), 0u);
  EXPECT_EQ(consumed, (std::vector<bool>{true, true}));
}

// COB-ID bit 29: a 29-bit CAN-ID (CAN 2.0B frame).
TEST_F(PdoTest, TwentyNineBitTpdo) {
  Start();
  Tpdo(1, {.entries = {0x60000108}, .type = 255, .cob_id = 0x7ABCDEF0});
  Operational();
  Set(0x6000, 1, 0x42);
  pdo->RequestTpdo(1);
  EXPECT_EQ(master.Take(), (Frames{"1ABCDEF0#42"}));
}

// Sub5 written while operational: the new period starts at the write; 0 stops the timer.
TEST_F(PdoTest, EventTimerWriteWhileOperationalRearms) {
  Start();
  Tpdo(1, {.entries = {0x60000108}, .type = 254, .event_timer_ms = 100});
  Operational();
  scheduler.Advance(30ms);
  ASSERT_EQ(W16(0x1800, 5, 50), SdoAbort::kNone);
  scheduler.Advance(110ms);
  ASSERT_EQ(W16(0x1800, 5, 0), SdoAbort::kNone);
  scheduler.Advance(1s);
  EXPECT_EQ(recorder.Take(), (Frames{"80ms 185#00", "130ms 185#00"}));
}

// Disabling a TPDO (bit 31) stops it at once; enabling it again restarts its event timer then.
TEST_F(PdoTest, DisablingAndEnablingATpdoWhileOperational) {
  Start();
  Tpdo(1, {.entries = {0x60000108}, .type = 254, .event_timer_ms = 100});
  Operational();
  scheduler.Advance(50ms);
  ASSERT_EQ(W32(0x1800, 1, 0xC0000185), SdoAbort::kNone);
  pdo->RequestTpdo(1);
  scheduler.Advance(100ms);
  ASSERT_EQ(W32(0x1800, 1, 0x40000185), SdoAbort::kNone);  // 150 ms
  scheduler.Advance(100ms);
  EXPECT_EQ(recorder.Take(), (Frames{"250ms 185#00"}));
}

// CiA 301 §7.3.2.2 table 51: no PDO outside operational. Leaving operational stops the event
// timers; entering it again starts them afresh.
TEST_F(PdoTest, TpdosRunInOperationalOnly) {
  Start();
  Tpdo(1, {.entries = {0x60000108}, .type = 254, .event_timer_ms = 100});
  Tpdo(2, {.entries = {0x60000108}, .type = 1});
  pdo->SetNmtState(NmtState::kPreOperational);
  pdo->RequestTpdo(1);
  pdo->OnSync(0);
  scheduler.Advance(500ms);
  Operational();  // 500 ms
  scheduler.Advance(150ms);
  pdo->SetNmtState(NmtState::kStopped);  // 650 ms
  pdo->RequestTpdo(1);
  pdo->OnSync(0);
  scheduler.Advance(350ms);
  pdo->SetNmtState(NmtState::kPreOperational);
  scheduler.Advance(100ms);
  Operational();  // 1100 ms
  scheduler.Advance(100ms);
  EXPECT_EQ(recorder.Take(), (Frames{"600ms 185#00", "1200ms 185#00"}));
}

// Mapping lengths are in bits (CiA 301 §7.5.2.38): 1-bit BOOLEANs share a byte with what follows.
TEST_F(PdoTest, BitGranularMappingPacksTpdoBits) {
  Start();
  Tpdo(1, {.entries = {0x20100001, 0x20110001, 0x20120001, 0x60000108}});
  Operational();
  Set(0x2010, 0, 1);
  Set(0x2012, 0, 1);
  Set(0x6000, 1, 0xFF);
  pdo->RequestTpdo(1);
  // bits 0-2 = 1,0,1; bits 3-10 = FFh → 0x07FD
  EXPECT_EQ(master.Take(), (Frames{"185#FD07"}));
}

// Sampling runs the mapped objects' read hooks (values computed on demand) with Origin::kPdo.
TEST_F(PdoTest, SamplingRunsReadHooks) {
  Start();
  Tpdo(1, {.entries = {0x71000110}});
  std::vector<Origin> origins;
  od.Find(0x7100, 1)->AddReadHook([&](SubObject& sub, Origin origin) {
    origins.push_back(origin);
    sub.value = EncodeLe<std::int16_t>(0x0102);
    return SdoAbort::kNone;
  });
  Operational();
  pdo->RequestTpdo(1);
  EXPECT_EQ(master.Take(), (Frames{"185#0201"}));
  EXPECT_EQ(origins, (std::vector<Origin>{Origin::kPdo}));
}

}  // namespace
}  // namespace canfleet::canopen::test_pdo
