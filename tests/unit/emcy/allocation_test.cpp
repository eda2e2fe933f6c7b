// Steady state does not allocate: raising and clearing errors, with and without the inhibit queue,
// reuses the reserved lists, the fixed frame ring and the OD values in place.
#include <gtest/gtest.h>

#include "clock/scheduler.hpp"
#include "node/canopen/emcy/emcy.hpp"
#include "tests/support/allocation_counter.hpp"

namespace canfleet::canopen {
namespace {

using namespace std::chrono_literals;

/// A port that accepts every frame and keeps nothing (the loopback bus has its own deques).
class NullPort final : public BusPort {
 public:
  bool Send(const CanFrame&) override {
    ++sent;
    return true;
  }
  ControllerState State() const override { return ControllerState::kErrorActive; }
  std::size_t sent = 0;
};

void RaiseAndClearFour(Emcy& emcy) {
  for (std::uint16_t channel = 1; channel <= 4; ++channel) {
    ErrorEntry e;
    e.code = 0x2320;
    e.info = static_cast<std::uint16_t>(0x0400 | channel);
    e.register_bits = kErrorRegisterCurrent;
    emcy.Raise(e);
  }
  for (std::uint16_t channel = 1; channel <= 4; ++channel) {
    emcy.Clear(0x2320, static_cast<std::uint16_t>(0x0400 | channel));
  }
}

TEST(EmcyAllocation, RaiseAndClearDoNotAllocateInSteadyState) {
  SimulatedScheduler scheduler;
  NullPort port;
  ObjectDictionary od;
  AddEmcyObjects(od, 4);
  od.RestoreDefaults(0x1000, 0x1FFF, 5);
  Emcy emcy(od, port, scheduler);
  emcy.SetNodeId(5);
  emcy.SetNmtState(NmtState::kOperational);
  emcy.OnSent([](const CanFrame&) {});
  RaiseAndClearFour(emcy);  // warm-up

  auto before = canfleet::test::AllocationCount();
  RaiseAndClearFour(emcy);
  EXPECT_EQ(canfleet::test::AllocationCount() - before, 0u);
  EXPECT_EQ(port.sent, 16u);

  // With an inhibit time the frames wait in the ring and a Timer sends them (the warm-up lets the
  // scheduler's heap take its first timer).
  ASSERT_EQ(od.Write(0x1015, 0, EncodeLe<std::uint16_t>(10)), SdoAbort::kNone);
  RaiseAndClearFour(emcy);
  scheduler.Advance(10ms);
  before = canfleet::test::AllocationCount();
  RaiseAndClearFour(emcy);
  scheduler.Advance(10ms);
  EXPECT_EQ(canfleet::test::AllocationCount() - before, 0u);
  EXPECT_EQ(port.sent, 32u);
}

}  // namespace
}  // namespace canfleet::canopen
