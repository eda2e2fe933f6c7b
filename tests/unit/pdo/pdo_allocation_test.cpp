// The PDO hot path does not allocate (CONTRIBUTING: re-arming a Timer does not allocate; the PDO
// mapping is resolved to SubObject pointers once per configuration change). Counts every
// operator new of this test binary while frames, SYNCs, events and timers run.
#include "tests/support/allocation_counter.hpp"
#include "tests/unit/pdo/pdo_fixture.hpp"

namespace canfleet::canopen::test_pdo {
namespace {

/// A bus port that keeps the last frame only: no allocation of its own.
class LastFramePort final : public BusPort {
 public:
  bool Send(const CanFrame& frame) override {
    last = frame;
    ++sent;
    return true;
  }
  ControllerState State() const override { return ControllerState::kErrorActive; }
  CanFrame last;
  std::uint64_t sent = 0;
};

class PdoAllocationTest : public PdoTest {
 protected:
  LastFramePort port;
};

TEST_F(PdoAllocationTest, HotPathDoesNotAllocate) {
  pdo = std::make_unique<PdoService>(od, port, scheduler, errors);
  PdoService& fast = *pdo;
  Rpdo(1, {.entries = {0x62000108, 0x73000110}, .type = 255, .event_timer_ms = 100});
  Rpdo(2, {.entries = {0x73000210}, .type = 1});
  Tpdo(1, {.entries = {0x60000108, 0x71000110}, .type = 254, .event_timer_ms = 10, .inhibit_100us = 20});
  Tpdo(2, {.entries = {0x71000210}, .type = 1});
  Tpdo(3, {.entries = {0x60000108}, .type = 0});
  fast.SetNmtState(NmtState::kOperational);
  const CanFrame rpdo1 = test::Frame("205#0134127856");
  const CanFrame rpdo2 = test::Frame("305#7856");
  auto round = [&] {
    fast.OnFrame(rpdo1);
    fast.OnFrame(rpdo2);
    fast.NotifyChanged(*di);
    fast.OnSync(0);
    scheduler.Advance(5ms);
  };
  round();  // warm-up: the scheduler's heap reaches its size
  const auto before = canfleet::test::AllocationCount();
  for (int i = 0; i < 100; ++i)
    round();
  EXPECT_EQ(canfleet::test::AllocationCount() - before, 0u);
  EXPECT_GT(port.sent, 300u);
  EXPECT_EQ(fast.Counters().rpdo_applied, 202u);
}

}  // namespace
}  // namespace canfleet::canopen::test_pdo
