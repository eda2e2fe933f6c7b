// PDO and SYNC together, as the stack wires them (SyncService::OnSync → PdoService::OnSync):
// CiA 301 v4.2 §7.2.2 (synchronous transmission) and §7.2.5 (SYNC).
#include "node/canopen/sync/sync_service.hpp"

#include "tests/unit/pdo/pdo_fixture.hpp"

namespace canfleet::canopen::test_pdo {
namespace {

class PdoSyncTest : public PdoTest {
 protected:
  void StartWithSync() {
    Start();
    sync = std::make_unique<SyncService>(od, node_port, scheduler, errors);
    sync->OnSync([this](std::uint8_t counter) { pdo->OnSync(counter); });
    node_port.OnReceive([this](const CanFrame& frame, BusTime) {
      if (!sync->OnFrame(frame)) consumed.push_back(pdo->OnFrame(frame));
    });
  }
  void Operational() {
    sync->SetNmtState(NmtState::kOperational);
    pdo->SetNmtState(NmtState::kOperational);
  }
  std::unique_ptr<SyncService> sync;
};

// The node produces SYNC every 10 ms with a counter 1..4: each SYNC is followed by the TPDOs it
// makes due — type 1 at every SYNC, type 2 from the SYNC with counter 3 (start value) on.
TEST_F(PdoSyncTest, ProducedSyncDrivesSynchronousTpdos) {
  StartWithSync();
  Tpdo(1, {.entries = {0x60000108}, .type = 1});
  Tpdo(2, {.entries = {0x71000110}, .type = 2, .sync_start = 3});
  ASSERT_EQ(W8(0x1019, 0, 4), SdoAbort::kNone);
  ASSERT_EQ(W32(0x1005, 0, 0x40000080), SdoAbort::kNone);
  ASSERT_EQ(W32(0x1006, 0, 10000), SdoAbort::kNone);
  Operational();
  scheduler.Advance(60ms);
  EXPECT_EQ(recorder.Take(),
            (Frames{"10ms 080#01", "10ms 185#00", "20ms 080#02", "20ms 185#00", "30ms 080#03", "30ms 185#00",
                    "30ms 285#0000", "40ms 080#04", "40ms 185#00", "50ms 080#01", "50ms 185#00",
                    "50ms 285#0000", "60ms 080#02", "60ms 185#00"}));
}

// A master's SYNC applies a synchronous RPDO received before it, and the synchronous TPDO sent
// at that SYNC already carries what was written (RPDOs are applied first).
TEST_F(PdoSyncTest, ConsumedSyncAppliesRpdosBeforeSendingTpdos) {
  StartWithSync();
  Rpdo(1, {.entries = {0x62000108}, .type = 1});
  Tpdo(1, {.entries = {0x62000108}, .type = 1});
  Operational();
  master.Send("205#2A");
  EXPECT_EQ(od.GetUnsigned(0x6200, 1), 0u);
  master.Send("080#");
  EXPECT_EQ(master.Take(), (Frames{"185#2A"}));
  EXPECT_EQ(consumed, (std::vector<bool>{true}));  // the SYNC went to the SYNC service
}

}  // namespace
}  // namespace canfleet::canopen::test_pdo
