// The device framework: the fixed tick, the delayed-fault life cycle shared by the manuals, a
// device with two CAN ports sharing its application objects (the data logger's shape, UMAX181001
// §1.1), DeviceNode's checks and the per-unit serial number.
#include <gtest/gtest.h>

#include "bus/loopback_bus.hpp"
#include "node/canopen/stack/standard_objects.hpp"
#include "node/devices/delayed_fault.hpp"
#include "node/devices/device_node.hpp"
#include "node/devices/od_ref.hpp"
#include "node/devices/periodic_tick.hpp"
#include "node/devices/quad_controller/quad_controller.hpp"
#include "node/devices/shared_objects.hpp"
#include "tests/support/bus_probe.hpp"

namespace canfleet::devices {
namespace {

using namespace std::chrono_literals;
using canopen::NmtState;

TEST(PeriodicTickTest, TicksEveryPeriodWithoutDrift) {
  SimulatedScheduler scheduler;
  std::vector<TimePoint> at;
  PeriodicTick tick(scheduler, 10ms, [&] { at.push_back(scheduler.Now()); });
  tick.Start();
  scheduler.Advance(35ms);
  ASSERT_EQ(at.size(), 3u);
  EXPECT_EQ(at[2] - TimePoint{}, 30ms);
  tick.Stop();
  scheduler.Advance(50ms);
  EXPECT_EQ(tick.Count(), 3u);
  EXPECT_THROW(PeriodicTick(scheduler, 0ms, [] {}), std::invalid_argument);
}

// A plain CiA 301 node with a 1029h of three entries, to drive DelayedFault by hand.
class DelayedFaultTest : public ::testing::Test {
 protected:
  DelayedFaultTest() {
    canopen::StandardObjectsOptions o;
    o.error_behaviour_subs = 3;
    canopen::AddStandardObjects(od_, o);
    canopen::StackOptions options;
    options.node_id = 9;
    stack_ = std::make_unique<canopen::CanopenStack>(od_, port_, scheduler_, options);
    stack_->Start();
    master_.Clear();
  }
  canopen::ErrorEntry Entry() const {
    canopen::ErrorEntry e;
    e.code = 0xFF00;
    e.info = 0x0102;
    e.msef = {2, 1, 0, 0, 0};
    return e;
  }
  SimulatedScheduler scheduler_;
  LoopbackBus bus_;
  LoopbackPort& port_ = bus_.Attach("node");
  canfleet::test::BusProbe master_{bus_, "master"};
  canopen::ObjectDictionary od_;
  std::unique_ptr<canopen::CanopenStack> stack_;
};

// AX020506 §4.2: inactive → pending (delay) → active (EMCY, 1003h, 1029h) → inactive.
TEST_F(DelayedFaultTest, PendingActiveAndBack) {
  od_.SetUnsigned(0x1029, 3, 2);
  master_.Send("000#0109");
  DelayedFault fault(scheduler_, *stack_, Entry(), 3);
  fault.Update(true, 100ms);
  EXPECT_EQ(fault.state(), DelayedFault::State::kPending);
  scheduler_.Advance(50ms);
  fault.Update(true, 100ms);  // still present: the timer keeps running
  scheduler_.Advance(50ms);
  EXPECT_TRUE(fault.Active());
  EXPECT_EQ(master_.Take(), std::vector<std::string>{"089#00FF010201000000"});
  EXPECT_EQ(od_.GetUnsigned(0x1003, 1), 0x0102FF00u);
  EXPECT_EQ(stack_->State(), NmtState::kStopped);
  fault.Update(false, 100ms);
  EXPECT_EQ(fault.state(), DelayedFault::State::kInactive);
  EXPECT_EQ(od_.GetUnsigned(0x1003, 0), 0u);
}

TEST_F(DelayedFaultTest, GoneWhilePendingOrResetLeavesNoTrace) {
  DelayedFault fault(scheduler_, *stack_, Entry(), 0);
  fault.Update(true, 100ms);
  scheduler_.Advance(99ms);
  fault.Update(false, 100ms);
  scheduler_.Advance(200ms);
  EXPECT_EQ(fault.state(), DelayedFault::State::kInactive);
  fault.Update(true, 0ms);
  EXPECT_TRUE(fault.Active());
  fault.Reset();
  EXPECT_EQ(fault.state(), DelayedFault::State::kInactive);
  EXPECT_EQ(stack_->State(), NmtState::kPreOperational);  // behaviour sub 0: no reaction
}

// A device with two CAN ports: each port has its own communication objects and NMT state; the
// application objects (2000h-FFFFh) are shared, the first port's dictionary holding the rules.
class TwoPortDevice final : public Device {
 public:
  std::string_view Name() const override { return "two-port"; }
  std::size_t PortCount() const override { return 2; }
  void Build(std::size_t port, canopen::ObjectDictionary& od) override {
    (void)port;
    canopen::AddStandardObjects(od, {});
    od.AddVar(0x2000, "Even parameter", canopen::DataType::kUnsigned16, canopen::Access::kRw,
              canopen::EncodeLe<std::uint16_t>(2));
    od.AddVar(0x6000, "Measured", canopen::DataType::kUnsigned8, canopen::Access::kRo, {0}, true);
  }
  void Attach(DeviceContext& context) override {
    auto& primary = context.stacks[0]->od();
    shared = std::make_unique<SharedObjects>(primary, context.stacks[1]->od(), 0x2000, 0xFFFF);
    primary.Find(0x2000, 0)->validators.push_back(
        [](const canopen::SubObject&, std::span<const std::uint8_t> d, canopen::Origin) {
          return d[0] % 2 == 0 ? canopen::SdoAbort::kNone : canopen::SdoAbort::kInvalidValue;
        });
    primary.Find(0x2000, 0)->listeners.push_back([this](canopen::SubObject&, canopen::Origin) { ++changes; });
    measured = OdRef(primary, 0x6000, 0);
  }
  std::unique_ptr<SharedObjects> shared;
  OdRef measured;
  int changes = 0;
};

class TwoPortTest : public ::testing::Test {
 protected:
  TwoPortTest()
      : node_(std::make_unique<TwoPortDevice>(), scheduler_, {&port1_, &port2_},
              NodeSettings{{PortSettings{3, 4}, PortSettings{4, 4}}, {}, {}, {}}) {
    node_.Start();
    can1_.Clear();
    can2_.Clear();
  }
  TwoPortDevice& device() { return static_cast<TwoPortDevice&>(node_.device()); }
  SimulatedScheduler scheduler_;
  LoopbackBus bus1_, bus2_;
  LoopbackPort& port1_ = bus1_.Attach("node");
  LoopbackPort& port2_ = bus2_.Attach("node");
  canfleet::test::BusProbe can1_{bus1_, "master1"};
  canfleet::test::BusProbe can2_{bus2_, "master2"};
  DeviceNode node_;
};

TEST_F(TwoPortTest, ApplicationObjectsAreSharedAndRulesApplyOnBothPorts) {
  EXPECT_EQ(node_.PortCount(), 2u);
  EXPECT_GT(device().shared->Count(), 0u);
  can2_.Send("604#2B00200008000000");  // port 2, node 4: 2000h = 8
  EXPECT_EQ(can2_.Next(), "584#6000200000000000");
  EXPECT_EQ(device().changes, 1);
  can1_.Send("603#4000200000000000");
  EXPECT_EQ(can1_.Next(), "583#4B00200008000000");
  can2_.Send("604#2B00200007000000");  // odd: the primary's validator refuses
  EXPECT_EQ(can2_.Next(), "584#8000200030000906");
  device().measured.Set(0x5A);  // a block writes the primary
  can2_.Send("604#4000600000000000");
  EXPECT_EQ(can2_.Next(), "584#4F0060005A000000");
}

TEST_F(TwoPortTest, EachPortHasItsOwnNmtState) {
  can1_.Send("000#0203");  // stop port 1's node
  EXPECT_EQ(node_.stack(0).State(), NmtState::kStopped);
  EXPECT_EQ(node_.stack(1).State(), NmtState::kPreOperational);
  can2_.Send("604#4000100000000000");
  EXPECT_EQ(can2_.Next().substr(0, 6), "584#43");
}

TEST(DeviceNodeTest, RefusesAWrongNumberOfPorts) {
  SimulatedScheduler scheduler;
  LoopbackBus bus;
  LoopbackPort& port = bus.Attach("node");
  EXPECT_THROW(DeviceNode(std::make_unique<TwoPortDevice>(), scheduler, {&port}, {}), std::invalid_argument);
}

// Each unit has its own serial number (1018h sub 4), kept by reset communication, so that LSS
// (CiA 305) can tell identical products apart.
TEST(DeviceNodeTest, SerialNumberOverridesTheEds) {
  SimulatedScheduler scheduler;
  LoopbackBus bus;
  LoopbackPort& port = bus.Attach("node");
  canfleet::test::BusProbe master(bus, "master");
  DeviceNode node(std::make_unique<QuadController>(), scheduler, {&port},
                  NodeSettings{{PortSettings{5, 4}}, {}, 0x12345678, {}});
  node.Start();
  master.Send("000#8205");  // reset communication
  master.Clear();
  master.Send("605#4018100400000000");
  EXPECT_EQ(master.Next(), "585#4318100478563412");
}

}  // namespace
}  // namespace canfleet::devices
