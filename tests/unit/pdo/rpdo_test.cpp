// RPDO reception: CiA 301 v4.2 §7.2.2 and §7.5.2.35/36 (1400h+/1600h+); length errors and the
// RPDO deadline as in facts §4 (CANopenNode CO_PDO_receive / CO_RPDO_process).
#include <algorithm>

#include "tests/unit/pdo/pdo_fixture.hpp"

namespace canfleet::canopen::test_pdo {
namespace {

class RpdoTest : public PdoTest {
 protected:
  // RPDO1 = DO (8 bits), AO1 (16), AO2 (16): 5 bytes.
  void MapRpdo1(std::uint8_t type = 255, std::uint16_t event_timer_ms = 0) {
    Rpdo(1,
         {.entries = {0x62000108, 0x73000110, 0x73000210}, .type = type, .event_timer_ms = event_timer_ms});
  }
};

// Event RPDO: written at once through the dictionary (Origin::kPdo), so device listeners run.
TEST_F(RpdoTest, EventRpdoIsWrittenAtOnceAndListenersRun) {
  Start();
  MapRpdo1();
  std::vector<std::string> seen;
  od.Find(0x7300, 1)->AddListener([&](SubObject& sub, Origin origin) {
    seen.push_back(std::to_string(DecodeSignedLe(sub.value)) + (origin == Origin::kPdo ? " pdo" : " other"));
  });
  Operational();
  master.Send("205#0134127856");
  master.Send("206#0134127856");  // another identifier
  EXPECT_EQ(od.GetUnsigned(0x6200, 1), 1u);
  EXPECT_EQ(od.GetSigned(0x7300, 1), 0x1234);
  EXPECT_EQ(od.GetSigned(0x7300, 2), 0x5678);
  EXPECT_EQ(seen, (std::vector<std::string>{"4660 pdo"}));
  EXPECT_EQ(consumed, (std::vector<bool>{true, false}));
  EXPECT_EQ(pdo->Counters().rpdo_received, 1u);
  EXPECT_EQ(pdo->Counters().rpdo_applied, 1u);
  EXPECT_TRUE(errors.events.empty());
}

// The acceptance filter (orchestrator/broker/README.md "Acceptance filters") follows the
// configuration, not the NMT state: a valid RPDO is listened to before the NMT start too, since
// no reply follows that start to carry a new filter; an invalid COB-ID (CiA 301 §7.5.2.35,
// bit 31) takes it out.
TEST_F(RpdoTest, ItsIdentifierIsListenedToInEveryNmtStateWhileItIsValid) {
  Start();
  MapRpdo1();
  auto listened = [&] {
    std::vector<std::uint32_t> ids;
    pdo->AddListenedIds(ids);
    return std::find(ids.begin(), ids.end(), 0x205u) != ids.end();
  };
  EXPECT_TRUE(listened()) << "pre-operational";
  Operational();
  EXPECT_TRUE(listened()) << "operational";
  pdo->SetNmtState(NmtState::kStopped);
  EXPECT_TRUE(listened()) << "stopped";
  ASSERT_EQ(W32(0x1400, 1, static_cast<std::uint32_t>(od.GetUnsigned(0x1400, 1)) | kPdoCobIdInvalid),
            SdoAbort::kNone);
  EXPECT_FALSE(listened()) << "invalid";
}

// Fewer bytes than mapped: nothing is written, EMCY 8210h once; the next right frame clears it.
TEST_F(RpdoTest, TooShortIsNotAppliedAndReportedOnce) {
  Start();
  MapRpdo1();
  Operational();
  master.Send("205#01341278");
  master.Send("205#01");
  EXPECT_EQ(od.GetUnsigned(0x6200, 1), 0u);
  EXPECT_EQ(errors.events, (Frames{"RpdoTooShort(1)+"}));
  master.Send("205#0234127856");
  EXPECT_EQ(errors.events, (Frames{"RpdoTooShort(1)+", "RpdoTooShort(1)-"}));
  EXPECT_EQ(od.GetUnsigned(0x6200, 1), 2u);
  EXPECT_EQ(pdo->Counters().rpdo_received, 3u);
  EXPECT_EQ(pdo->Counters().rpdo_applied, 1u);
}

// More bytes than mapped: written, EMCY 8220h once; a switch to too short swaps the errors.
TEST_F(RpdoTest, TooLongIsAppliedAndReported) {
  Start();
  MapRpdo1();
  Operational();
  master.Send("205#0334127856AA");
  master.Send("205#0434127856AABB");
  EXPECT_EQ(od.GetUnsigned(0x6200, 1), 4u);
  EXPECT_EQ(errors.events, (Frames{"RpdoTooLong(1)+"}));
  master.Send("205#05");
  master.Send("205#0634127856AA");
  master.Send("205#0734127856");
  EXPECT_EQ(od.GetUnsigned(0x6200, 1), 7u);
  EXPECT_EQ(errors.events, (Frames{"RpdoTooLong(1)+", "RpdoTooLong(1)-", "RpdoTooShort(1)+",
                                   "RpdoTooShort(1)-", "RpdoTooLong(1)+", "RpdoTooLong(1)-"}));
}

// Types 0–240: the data is written at the next SYNC (facts §4), the last frame before it winning.
TEST_F(RpdoTest, SynchronousRpdoIsAppliedAtTheNextSync) {
  Start();
  MapRpdo1(1);
  Rpdo(2, {.entries = {0x73000310}, .type = 0});
  Operational();
  master.Send("205#0134127856");
  master.Send("205#0234127856");
  master.Send("305#3412");
  EXPECT_EQ(od.GetUnsigned(0x6200, 1), 0u);
  EXPECT_EQ(od.GetSigned(0x7300, 3), 0);
  pdo->OnSync(0);
  EXPECT_EQ(od.GetUnsigned(0x6200, 1), 2u);
  EXPECT_EQ(od.GetSigned(0x7300, 3), 0x1234);
  Set(0x6200, 1, 9);
  pdo->OnSync(0);  // nothing new received
  EXPECT_EQ(od.GetUnsigned(0x6200, 1), 9u);
  EXPECT_EQ(pdo->Counters().rpdo_received, 3u);
  EXPECT_EQ(pdo->Counters().rpdo_applied, 2u);
}

// CiA 301 §7.5.2.7: a synchronous RPDO received after the window (1007h µs after the SYNC) closed
// is dropped.
TEST_F(RpdoTest, SynchronousRpdoOutsideTheWindowIsDropped) {
  Start();
  ASSERT_EQ(W32(0x1007, 0, 1000), SdoAbort::kNone);
  MapRpdo1(1);
  Operational();
  pdo->OnSync(0);
  scheduler.Advance(1000us);
  master.Send("205#0134127856");  // at the window's end: inside
  pdo->OnSync(0);
  EXPECT_EQ(od.GetUnsigned(0x6200, 1), 1u);
  scheduler.Advance(1001us);
  master.Send("205#0234127856");  // 1001 µs after the SYNC
  pdo->OnSync(0);
  EXPECT_EQ(od.GetUnsigned(0x6200, 1), 1u);
  EXPECT_EQ(pdo->Counters().rpdo_received, 2u);
  EXPECT_EQ(pdo->Counters().rpdo_applied, 1u);
}

// Sub5 as an RPDO deadline: monitoring starts with the first frame; a gap longer than 50 ms
// reports the timeout once at exactly the last frame + 50 ms; the next frame clears it.
TEST_F(RpdoTest, DeadlineExpiresAndRecovers) {
  Start();
  MapRpdo1(255, 50);
  Operational();
  scheduler.Advance(200ms);
  EXPECT_TRUE(errors.events.empty());  // nothing received yet: not monitored
  master.Send("205#0134127856");       // 200 ms
  scheduler.Advance(30ms);
  master.Send("205#0134127856");  // 230 ms
  scheduler.Advance(49999us);
  EXPECT_TRUE(errors.events.empty());
  scheduler.Advance(1us);  // 280 ms
  EXPECT_EQ(errors.events, (Frames{"RpdoTimeout(1)+"}));
  scheduler.Advance(20ms);
  master.Send("205#0134127856");  // 300 ms
  EXPECT_EQ(errors.events, (Frames{"RpdoTimeout(1)+", "RpdoTimeout(1)-"}));
  scheduler.Advance(49999us);
  EXPECT_EQ(errors.events.size(), 2u);
  scheduler.Advance(1us);  // 350 ms
  scheduler.Advance(1s);
  EXPECT_EQ(errors.events, (Frames{"RpdoTimeout(1)+", "RpdoTimeout(1)-", "RpdoTimeout(1)+"}));
}

// A too-short frame is not a reception for the deadline (CANopenNode: only accepted frames
// restart the timeout timer).
TEST_F(RpdoTest, TooShortFrameDoesNotFeedTheDeadline) {
  Start();
  MapRpdo1(255, 50);
  Operational();
  master.Send("205#0134127856");
  scheduler.Advance(40ms);
  master.Send("205#01");
  scheduler.Advance(10ms);
  EXPECT_EQ(errors.events, (Frames{"RpdoTooShort(1)+", "RpdoTimeout(1)+"}));
}

// Leaving operational stops monitoring but leaves a pending timeout for the next frame to clear
// (1029h may be what left operational); back in operational monitoring waits for a first frame.
TEST_F(RpdoTest, DeadlineStopsOutsideOperationalAndTimeoutPersists) {
  Start();
  MapRpdo1(255, 50);
  Operational();
  master.Send("205#0134127856");
  scheduler.Advance(10ms);
  pdo->SetNmtState(NmtState::kPreOperational);
  scheduler.Advance(100ms);
  EXPECT_TRUE(errors.events.empty());
  Operational();
  scheduler.Advance(100ms);
  EXPECT_TRUE(errors.events.empty());
  master.Send("205#0134127856");
  scheduler.Advance(50ms);
  pdo->SetNmtState(NmtState::kPreOperational);
  master.Send("205#0134127856");  // not taken in pre-operational
  Operational();
  EXPECT_EQ(errors.events, (Frames{"RpdoTimeout(1)+"}));
  master.Send("205#0134127856");
  EXPECT_EQ(errors.events, (Frames{"RpdoTimeout(1)+", "RpdoTimeout(1)-"}));
}

// Nobody watches a disabled RPDO, or one whose event timer is 0: a pending timeout is cleared.
TEST_F(RpdoTest, DisablingTheRpdoOrItsDeadlineClearsTheTimeout) {
  Start();
  MapRpdo1(255, 50);
  Operational();
  master.Send("205#0134127856");
  scheduler.Advance(50ms);
  ASSERT_EQ(W32(0x1400, 1, 0xC0000205), SdoAbort::kNone);
  EXPECT_EQ(errors.events, (Frames{"RpdoTimeout(1)+", "RpdoTimeout(1)-"}));
  ASSERT_EQ(W32(0x1400, 1, 0x40000205), SdoAbort::kNone);
  master.Send("205#0134127856");
  scheduler.Advance(50ms);
  ASSERT_EQ(W16(0x1400, 5, 0), SdoAbort::kNone);
  EXPECT_EQ(errors.events,
            (Frames{"RpdoTimeout(1)+", "RpdoTimeout(1)-", "RpdoTimeout(1)+", "RpdoTimeout(1)-"}));
}

// A new event timer value moves a running deadline to last reception + new value.
TEST_F(RpdoTest, EventTimerWriteMovesTheDeadline) {
  Start();
  MapRpdo1(255, 50);
  Operational();
  master.Send("205#0134127856");
  scheduler.Advance(20ms);
  ASSERT_EQ(W16(0x1400, 5, 100), SdoAbort::kNone);
  scheduler.Advance(79999us);
  EXPECT_TRUE(errors.events.empty());
  scheduler.Advance(1us);  // 100 ms
  EXPECT_EQ(errors.events, (Frames{"RpdoTimeout(1)+"}));
}

// CiA 301 §7.3.2.2 table 51: RPDOs only in operational; leaving it drops SYNC-buffered data.
TEST_F(RpdoTest, RpdosRunInOperationalOnly) {
  Start();
  MapRpdo1();
  Rpdo(2, {.entries = {0x73000310}, .type = 1});
  pdo->SetNmtState(NmtState::kPreOperational);
  master.Send("205#0134127856");
  pdo->SetNmtState(NmtState::kStopped);
  master.Send("205#0134127856");
  EXPECT_EQ(od.GetUnsigned(0x6200, 1), 0u);
  Operational();
  master.Send("305#3412");
  pdo->SetNmtState(NmtState::kPreOperational);
  Operational();
  pdo->OnSync(0);
  EXPECT_EQ(od.GetSigned(0x7300, 3), 0);
  EXPECT_EQ(consumed, (std::vector<bool>{false, false, true}));
  EXPECT_EQ(pdo->Counters().rpdo_received, 1u);
  EXPECT_EQ(pdo->Counters().rpdo_applied, 0u);
}

// COB-ID bit 29: the RPDO listens to the 29-bit identifier only.
TEST_F(RpdoTest, TwentyNineBitRpdo) {
  Start();
  Rpdo(1, {.entries = {0x62000108}, .cob_id = 0x60000205});
  Operational();
  master.Send("205#01");
  EXPECT_EQ(od.GetUnsigned(0x6200, 1), 0u);
  master.Send("00000205#02");
  EXPECT_EQ(od.GetUnsigned(0x6200, 1), 2u);
  EXPECT_EQ(consumed, (std::vector<bool>{false, true}));
}

// Bit-granular mapping: 1-bit BOOLEANs and an INTEGER16 at bit 2; a signed object mapped with
// fewer bits than it holds is sign-extended.
TEST_F(RpdoTest, BitGranularMappingUnpacksBits) {
  Start();
  Rpdo(1, {.entries = {0x20100001, 0x20110001, 0x73000110}});
  Rpdo(2, {.entries = {0x73000208}});
  Set(0x2011, 0, 1);
  Operational();
  master.Send("205#050002");  // 1 | 0 << 1 | 8001h << 2
  master.Send("305#FF");
  EXPECT_EQ(od.GetUnsigned(0x2010, 0), 1u);
  EXPECT_EQ(od.GetUnsigned(0x2011, 0), 0u);
  EXPECT_EQ(od.GetSigned(0x7300, 1), -32767);
  EXPECT_EQ(od.GetSigned(0x7300, 2), -1);
  EXPECT_TRUE(errors.events.empty());
}

// Origin::kPdo writes obey limits and validators: a refused object keeps its value, the other
// mapped objects are still written.
TEST_F(RpdoTest, RefusedObjectKeepsItsValue) {
  Start();
  MapRpdo1();
  od.Find(0x7300, 1)->high_limit = EncodeLe<std::int16_t>(1000);
  od.Find(0x7300, 2)->AddValidator(
      [](const SubObject&, std::span<const std::uint8_t>, Origin) { return SdoAbort::kLocalControl; });
  Operational();
  master.Send("205#01D0077856");  // AO1 = 2000 > 1000
  EXPECT_EQ(od.GetUnsigned(0x6200, 1), 1u);
  EXPECT_EQ(od.GetSigned(0x7300, 1), 0);
  EXPECT_EQ(od.GetSigned(0x7300, 2), 0);
  EXPECT_EQ(pdo->Counters().rpdo_applied, 1u);
}

}  // namespace
}  // namespace canfleet::canopen::test_pdo
