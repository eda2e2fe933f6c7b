// SYNC consumer and producer, CiA 301 v4.2 §7.2.5 (SYNC object) and §7.5.2.5–7 (1005h–1007h),
// 1019h (synchronous counter overflow value); facts sheet §8.
#include "node/canopen/sync/sync_service.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "tests/support/bus_probe.hpp"

namespace canfleet::canopen {
namespace {

using namespace std::chrono_literals;

class RecordingErrors final : public CommErrorSink {
 public:
  void OnCommError(const CommError& error, bool active) override {
    std::string text = error.kind == CommErrorKind::kSyncLength ? "SyncLength" : "Other";
    events.push_back(text + "(" + std::to_string(error.detail) + (active ? ")+" : ")-"));
  }
  std::vector<std::string> events;
};

class SyncServiceTest : public ::testing::Test {
 protected:
  void Build(bool producer_objects = true) {
    AddSyncObjects(od, producer_objects);
    Start();
  }
  // Builds the service on the dictionary as it is (even without SYNC objects).
  void Start() {
    sync = std::make_unique<SyncService>(od, node_port, scheduler, errors);
    node_port.OnReceive([this](const CanFrame& frame, BusTime) { consumed.push_back(sync->OnFrame(frame)); });
    sync->OnSync([this](std::uint8_t counter) {
      syncs.push_back(std::to_string(Micros()) + "us:" + std::to_string(counter));
    });
  }
  std::int64_t Micros() const {
    return std::chrono::duration_cast<std::chrono::microseconds>(scheduler.Now().time_since_epoch()).count();
  }
  SdoAbort Write32(std::uint16_t index, std::uint32_t value) {
    return od.Write(index, 0, EncodeLe<std::uint32_t>(value));
  }
  SdoAbort Write8(std::uint16_t index, std::uint8_t value) { return od.Write(index, 0, Bytes{value}); }

  SimulatedScheduler scheduler;
  LoopbackBus bus;
  LoopbackPort& node_port = bus.Attach("node");
  test::BusProbe master{bus, "master"};
  ObjectDictionary od;
  RecordingErrors errors;
  std::unique_ptr<SyncService> sync;
  std::vector<std::string> syncs;  // "<time>us:<counter>" per listener call
  std::vector<bool> consumed;      // OnFrame results
};

// CiA 301 §7.5.2.5–7 and 1019h defaults: COB-ID 080h consumer, no period, no window, no counter.
TEST_F(SyncServiceTest, AddSyncObjectsCreatesTheCiA301Defaults) {
  AddSyncObjects(od, false);
  EXPECT_EQ(od.GetUnsigned(0x1005, 0), 0x80u);
  EXPECT_EQ(od.Find(0x1006, 0), nullptr);
  EXPECT_EQ(od.GetUnsigned(0x1007, 0), 0u);
  EXPECT_EQ(od.GetUnsigned(0x1019, 0), 0u);
  AddSyncObjects(od, true);
  ASSERT_NE(od.Find(0x1006, 0), nullptr);
  EXPECT_EQ(od.GetUnsigned(0x1006, 0), 0u);
  EXPECT_EQ(od.Find(0x1005, 0)->access, Access::kRw);
}

// CiA 301 §7.3.2.2 table 51: SYNC in pre-operational and operational, not in stopped.
TEST_F(SyncServiceTest, ConsumesSyncInPreOperationalAndOperationalOnly) {
  Build();
  master.Send("080#");
  EXPECT_TRUE(syncs.empty());  // initialising: not started yet
  sync->SetNmtState(NmtState::kPreOperational);
  master.Send("080#");
  sync->SetNmtState(NmtState::kOperational);
  scheduler.Advance(1ms);
  master.Send("080#");
  sync->SetNmtState(NmtState::kStopped);
  master.Send("080#");
  EXPECT_EQ(syncs, (std::vector<std::string>{"0us:0", "1000us:0"}));
  EXPECT_EQ(consumed, (std::vector<bool>{false, true, true, false}));
  EXPECT_TRUE(errors.events.empty());
}

// 1019h = 2..240: the SYNC carries the counter in byte 0 (DLC 1).
TEST_F(SyncServiceTest, PassesTheCounterWhenTheOverflowValueIsSet) {
  Build();
  ASSERT_EQ(Write8(0x1019, 5), SdoAbort::kNone);
  sync->SetNmtState(NmtState::kOperational);
  master.Send("080#03");
  master.Send("080#04");
  EXPECT_EQ(syncs, (std::vector<std::string>{"0us:3", "0us:4"}));
}

// Facts §8 (LELY, CANopenNode): a SYNC with the wrong DLC is not a SYNC; EMCY 8240h once, cleared
// by the next good SYNC.
TEST_F(SyncServiceTest, WrongDlcIsReportedOnceIgnoredAndClearedByTheNextGoodSync) {
  Build();
  sync->SetNmtState(NmtState::kPreOperational);
  master.Send("080#01");  // 1019h = 0 expects DLC 0
  master.Send("080#0102");
  EXPECT_TRUE(syncs.empty());
  EXPECT_EQ(errors.events, (std::vector<std::string>{"SyncLength(0)+"}));
  master.Send("080#");
  EXPECT_EQ(errors.events, (std::vector<std::string>{"SyncLength(0)+", "SyncLength(0)-"}));
  EXPECT_EQ(syncs, (std::vector<std::string>{"0us:0"}));
  EXPECT_EQ(consumed, (std::vector<bool>{true, true, true}));

  ASSERT_EQ(Write8(0x1019, 4), SdoAbort::kNone);
  master.Send("080#");  // a counter is expected now
  EXPECT_EQ(errors.events.back(), "SyncLength(0)+");
  EXPECT_EQ(syncs.size(), 1u);
}

// 1019h: 1 and 241..255 are reserved (06090030h); a change while 1006h ≠ 0 is refused with
// 08000022h (CANopenNode OD_write_1019).
TEST_F(SyncServiceTest, CounterOverflowWriteRules) {
  Build();
  EXPECT_EQ(Write8(0x1019, 1), SdoAbort::kInvalidValue);
  EXPECT_EQ(Write8(0x1019, 241), SdoAbort::kInvalidValue);
  EXPECT_EQ(Write8(0x1019, 255), SdoAbort::kInvalidValue);
  EXPECT_EQ(Write8(0x1019, 240), SdoAbort::kNone);
  EXPECT_EQ(Write8(0x1019, 0), SdoAbort::kNone);
  EXPECT_EQ(Write8(0x1019, 2), SdoAbort::kNone);
  ASSERT_EQ(Write32(0x1006, 1000), SdoAbort::kNone);
  EXPECT_EQ(Write8(0x1019, 3), SdoAbort::kDeviceState);
  EXPECT_EQ(od.GetUnsigned(0x1019, 0), 2u);
}

// 1005h (facts §8, CANopenNode OD_write_1005, LELY 29-bit bit): restricted CAN-IDs, bits 28–11
// with an 11-bit ID, and a CAN-ID change while producing are refused with 06090030h.
TEST_F(SyncServiceTest, CobIdWriteRules) {
  Build();
  EXPECT_EQ(Write32(0x1005, 0x00000000), SdoAbort::kInvalidValue);  // 000h: NMT
  EXPECT_EQ(Write32(0x1005, 0x0000007F), SdoAbort::kInvalidValue);
  EXPECT_EQ(Write32(0x1005, 0x00000701), SdoAbort::kInvalidValue);  // heartbeat
  EXPECT_EQ(Write32(0x1005, 0x00000581), SdoAbort::kInvalidValue);  // SDO
  EXPECT_EQ(Write32(0x1005, 0x00000880), SdoAbort::kInvalidValue);  // bit 11 with an 11-bit ID
  EXPECT_EQ(Write32(0x1005, 0x20000880), SdoAbort::kNone);          // 29-bit ID 880h
  EXPECT_EQ(Write32(0x1005, 0x00000081), SdoAbort::kNone);
  EXPECT_EQ(Write32(0x1005, 0x40000081), SdoAbort::kNone);  // start producing on 081h
  EXPECT_EQ(Write32(0x1005, 0x40000082), SdoAbort::kInvalidValue);
  EXPECT_EQ(Write32(0x1005, 0x60000081), SdoAbort::kInvalidValue);  // frame format is part of the ID
  EXPECT_EQ(Write32(0x1005, 0x00000082), SdoAbort::kNone);          // stop producing and move at once
  EXPECT_EQ(od.GetUnsigned(0x1005, 0), 0x82u);
}

// CiA 301 §7.2.5 and 1006h: the producer sends every 1006h µs, DLC 0 without a counter, and
// dispatches its own SYNC locally.
TEST_F(SyncServiceTest, ProducerSendsEveryPeriodWithoutDrift) {
  Build();
  ASSERT_EQ(Write32(0x1005, 0x40000080), SdoAbort::kNone);
  ASSERT_EQ(Write32(0x1006, 10000), SdoAbort::kNone);
  EXPECT_FALSE(sync->Producing());  // initialising
  sync->SetNmtState(NmtState::kPreOperational);
  EXPECT_TRUE(sync->Producing());
  scheduler.Advance(9999us);
  EXPECT_EQ(master.Count(), 0u);
  scheduler.Advance(1us);
  EXPECT_EQ(master.Take(), (std::vector<std::string>{"080#"}));
  scheduler.Advance(20ms);
  EXPECT_EQ(master.Take(), (std::vector<std::string>{"080#", "080#"}));
  EXPECT_EQ(syncs, (std::vector<std::string>{"10000us:0", "20000us:0", "30000us:0"}));
}

// 1019h: the producer's counter runs 1..1019h and wraps to 1 (facts §8).
TEST_F(SyncServiceTest, ProducerCounterWrapsAtTheOverflowValue) {
  Build();
  ASSERT_EQ(Write8(0x1019, 3), SdoAbort::kNone);
  ASSERT_EQ(Write32(0x1005, 0x40000080), SdoAbort::kNone);
  ASSERT_EQ(Write32(0x1006, 1000), SdoAbort::kNone);
  sync->SetNmtState(NmtState::kOperational);
  scheduler.Advance(5ms);
  EXPECT_EQ(master.Take(), (std::vector<std::string>{"080#01", "080#02", "080#03", "080#01", "080#02"}));
  EXPECT_EQ(syncs, (std::vector<std::string>{"1000us:1", "2000us:2", "3000us:3", "4000us:1", "5000us:2"}));
}

// Table 51: no SYNC production in stopped; production restarts one period after re-entering
// pre-operational, with the counter back at 1.
TEST_F(SyncServiceTest, ProducerStopsInStoppedAndRestartsWithCounterOne) {
  Build();
  ASSERT_EQ(Write8(0x1019, 10), SdoAbort::kNone);
  ASSERT_EQ(Write32(0x1005, 0x40000080), SdoAbort::kNone);
  ASSERT_EQ(Write32(0x1006, 1000), SdoAbort::kNone);
  sync->SetNmtState(NmtState::kOperational);
  scheduler.Advance(2ms);
  sync->SetNmtState(NmtState::kStopped);
  scheduler.Advance(10ms);
  EXPECT_EQ(master.Take(), (std::vector<std::string>{"080#01", "080#02"}));
  sync->SetNmtState(NmtState::kPreOperational);  // t = 12 ms
  scheduler.Advance(999us);
  EXPECT_EQ(master.Count(), 0u);
  scheduler.Advance(1us);
  EXPECT_EQ(master.Take(), (std::vector<std::string>{"080#01"}));
}

// 1006h written while producing: the next SYNC is one new period after the write.
TEST_F(SyncServiceTest, PeriodWriteWhileProducingRearmsFromTheWrite) {
  Build();
  ASSERT_EQ(Write32(0x1005, 0x40000080), SdoAbort::kNone);
  ASSERT_EQ(Write32(0x1006, 10000), SdoAbort::kNone);
  sync->SetNmtState(NmtState::kOperational);
  scheduler.Advance(25ms);
  ASSERT_EQ(Write32(0x1006, 2000), SdoAbort::kNone);
  scheduler.Advance(4ms);
  ASSERT_EQ(Write32(0x1006, 0), SdoAbort::kNone);  // 0 stops production
  scheduler.Advance(10ms);
  EXPECT_EQ(syncs, (std::vector<std::string>{"10000us:0", "20000us:0", "27000us:0", "29000us:0"}));
  EXPECT_FALSE(sync->Producing());
}

// 29-bit COB-ID SYNC (1005h bit 29, LELY): produced and consumed as extended frames only.
TEST_F(SyncServiceTest, TwentyNineBitSync) {
  Build();
  ASSERT_EQ(Write32(0x1005, 0x20000080), SdoAbort::kNone);
  sync->SetNmtState(NmtState::kOperational);
  master.Send("080#");       // 11-bit 080h: not the SYNC any more
  master.Send("00000080#");  // 29-bit 080h
  EXPECT_EQ(consumed, (std::vector<bool>{false, true}));
  EXPECT_EQ(syncs.size(), 1u);
  ASSERT_EQ(Write32(0x1005, 0x60000080), SdoAbort::kNone);
  ASSERT_EQ(Write32(0x1006, 1000), SdoAbort::kNone);
  scheduler.Advance(1ms);
  EXPECT_EQ(master.Take(), (std::vector<std::string>{"00000080#"}));
}

// A producer does not take a second time base from the bus: a SYNC from another node on its
// COB-ID is ignored (but recognised as SYNC, so not offered to other services).
TEST_F(SyncServiceTest, ProducerIgnoresForeignSync) {
  Build();
  ASSERT_EQ(Write32(0x1005, 0x40000080), SdoAbort::kNone);
  sync->SetNmtState(NmtState::kOperational);
  master.Send("080#");
  EXPECT_EQ(consumed, (std::vector<bool>{true}));
  EXPECT_TRUE(syncs.empty());
}

// A remote frame on 080h is not a SYNC.
TEST_F(SyncServiceTest, RemoteFrameIsNotASync) {
  Build();
  sync->SetNmtState(NmtState::kOperational);
  master.Send("080#R");
  EXPECT_EQ(consumed, (std::vector<bool>{false}));
  EXPECT_TRUE(syncs.empty());
}

// A service tolerates missing objects: without 1005h the node consumes SYNC on 080h (pre-defined
// connection set), never produces, and has no window.
TEST_F(SyncServiceTest, WithoutSyncObjectsConsumesOn080h) {
  Start();
  sync->SetNmtState(NmtState::kOperational);
  master.Send("080#");
  EXPECT_EQ(syncs, (std::vector<std::string>{"0us:0"}));
  EXPECT_TRUE(sync->InsideWindow());
  EXPECT_FALSE(sync->Producing());
}

// CiA 301 §7.5.2.7: the synchronous window is 1007h µs after each SYNC; 0 = no window.
TEST_F(SyncServiceTest, InsideWindowFollows1007h) {
  Build();
  sync->SetNmtState(NmtState::kOperational);
  EXPECT_TRUE(sync->InsideWindow());  // 1007h = 0
  ASSERT_EQ(Write32(0x1007, 500), SdoAbort::kNone);
  EXPECT_FALSE(sync->InsideWindow());  // no SYNC yet
  scheduler.Advance(1ms);
  master.Send("080#");
  EXPECT_TRUE(sync->InsideWindow());
  scheduler.Advance(500us);
  EXPECT_TRUE(sync->InsideWindow());
  scheduler.Advance(1us);
  EXPECT_FALSE(sync->InsideWindow());
  master.Send("080#");
  EXPECT_TRUE(sync->InsideWindow());
  ASSERT_TRUE(sync->LastSync().has_value());
  EXPECT_EQ(sync->LastSync()->time_since_epoch(), 1501us);
}

// Several listeners (the PDO service is one) see every SYNC, in the order they were added.
TEST_F(SyncServiceTest, ListenersRunInOrder) {
  Build();
  std::string order;
  sync->OnSync([&](std::uint8_t) { order += 'a'; });
  sync->OnSync([&](std::uint8_t) { order += 'b'; });
  sync->SetNmtState(NmtState::kOperational);
  master.Send("080#");
  master.Send("080#");
  EXPECT_EQ(order, "abab");
  EXPECT_EQ(syncs.size(), 2u);
}

}  // namespace
}  // namespace canfleet::canopen
