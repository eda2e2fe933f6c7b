// The frame path does not allocate once warmed up (issue 4, "Performance": pre-sized rings,
// reused batch buffers): steady traffic through paced and unpaced buses, with a fault rule.
#include <gtest/gtest.h>

#include "orchestrator/broker/broker.hpp"
#include "tests/support/allocation_counter.hpp"
#include "tests/unit/broker/broker_test_support.hpp"

namespace canfleet::broker {
namespace {

using namespace test;

/// Re-submits a frame for each confirmed one: constant offered load, no allocation of its own.
class Echo : public PortSink {
 public:
  Echo(Broker& broker, CanFrame frame) : broker_(broker), frame_(frame) {}
  void Deliver(std::span<const TimedFrame> frames) override { received += frames.size(); }
  void ControllerChanged(const ControllerEvent&) override {}
  void TxConfirmed(std::span<const TimedFrame> frames) override {
    for (std::size_t i = 0; i < frames.size(); ++i)
      broker_.Submit(id, frame_);
  }
  PortId id = 0;
  std::size_t received = 0;

 private:
  Broker& broker_;
  CanFrame frame_;
};

void ExpectNoAllocationInSteadyState(bool paced) {
  SimulatedScheduler s;
  Broker broker(s);
  broker.AddBus({.name = "can0", .bitrate = 1'000'000, .paced = paced});
  Echo a(broker, Frame("181#0102030405060708")), b(broker, Frame("182#01")), c(broker, Frame("701#05"));
  a.id = broker.Attach("can0", "a", a);
  b.id = broker.Attach("can0", "b", b);
  c.id = broker.Attach("can0", "c", c);
  broker.Faults("can0").Add({.id = 0x701, .mask = 0x7FF, .action = RuleAction::kDrop, .probability = 0.5});
  for (Echo* e : {&a, &b, &c})
    for (int i = 0; i < 8; ++i)
      broker.Submit(e->id, Frame("123#"));
  auto step = [&] {
    if (paced)
      s.Advance(100ms);
    else
      for (int i = 0; i < 200; ++i)
        s.Advance(1ns);  // one round per nanosecond (see Unpaced.RepliesFromInsideDeliverGoInTheNextRound)
  };
  step();  // warm-up: buffers reach their working size
  const auto before = canfleet::test::AllocationCount();
  const std::size_t received = a.received + b.received + c.received;
  step();
  const auto allocations = canfleet::test::AllocationCount() - before;
  EXPECT_EQ(allocations, 0u);
  // Traffic did flow (on the paced bus a's 181h, always pending, wins every arbitration).
  EXPECT_GT(a.received + b.received + c.received - received, 500u);
}

TEST(BrokerAllocation, PacedFramePathDoesNotAllocate) {
  ExpectNoAllocationInSteadyState(true);
}

TEST(BrokerAllocation, UnpacedFramePathDoesNotAllocate) {
  ExpectNoAllocationInSteadyState(false);
}

}  // namespace
}  // namespace canfleet::broker
