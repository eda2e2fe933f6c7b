// The PDO hot path does not allocate (CONTRIBUTING: re-arming a Timer does not allocate; the PDO
// mapping is resolved to SubObject pointers once per configuration change). Counts every
// operator new of this test binary while frames, SYNCs, events and timers run.
#include <atomic>
#include <cstdlib>
#include <new>

#include "tests/unit/pdo/pdo_fixture.hpp"

namespace {
std::atomic<std::uint64_t> g_allocations{0};
}  // namespace

void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) {
  return operator new(size);
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}

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
  const auto before = g_allocations.load();
  for (int i = 0; i < 100; ++i)
    round();
  EXPECT_EQ(g_allocations.load() - before, 0u);
  EXPECT_GT(port.sent, 300u);
  EXPECT_EQ(fast.Counters().rpdo_applied, 202u);
}

}  // namespace
}  // namespace canfleet::canopen::test_pdo
