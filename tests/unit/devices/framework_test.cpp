// The device framework: the fixed tick, the delayed-fault life cycle shared by the manuals, a
// device with two CAN ports sharing its application objects (the data logger's shape, UMAX181001
// §1.1), DeviceNode's checks and the per-unit serial number.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>

#include "bus/loopback_bus.hpp"
#include "node/canopen/stack/standard_objects.hpp"
#include "node/devices/delayed_fault.hpp"
#include "node/devices/device_node.hpp"
#include "node/devices/od_ref.hpp"
#include "node/devices/periodic_tick.hpp"
#include "node/devices/quad_controller/quad_controller.hpp"
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
// application objects (2000h-FFFFh) are one set, owned by the first port's dictionary and borrowed
// by the second's (the data logger's shape, UMAX181001 §1.1).
class TwoPortDevice final : public Device {
 public:
  TwoPortDevice() : Device(2) {}
  std::string_view Name() const override { return "two-port"; }
  std::optional<ObjectRange> SharedObjects() const override { return ObjectRange{0x2000, 0xFFFF}; }
  void Build(std::size_t port, canopen::ObjectDictionary& od) override {
    (void)port;
    canopen::AddStandardObjects(od, {});
    od.AddVar(0x2000, "Even parameter", canopen::DataType::kUnsigned16, canopen::Access::kRw,
              canopen::EncodeLe<std::uint16_t>(2));
    od.AddVar(0x6000, "Measured", canopen::DataType::kUnsigned8, canopen::Access::kRo, {0}, true);
  }
  void Attach(DeviceContext& context) override {
    auto& od = context.stacks[0]->od();
    od.Find(0x2000, 0)->AddValidator(
        [](const canopen::SubObject&, std::span<const std::uint8_t> d, canopen::Origin) {
          return d[0] % 2 == 0 ? canopen::SdoAbort::kNone : canopen::SdoAbort::kInvalidValue;
        });
    od.Find(0x2000, 0)->AddListener([this](canopen::SubObject&, canopen::Origin) { ++changes; });
    measured = OdRef(od, 0x6000, 0);
  }
  OdRef measured;
  int changes = 0;
};

class TwoPortTest : public ::testing::Test {
 protected:
  explicit TwoPortTest(std::filesystem::path state_dir = {}) : state_dir_(std::move(state_dir)) { Boot(); }
  void Boot() {
    node_.reset();
    node_ = std::make_unique<DeviceNode>(
        std::make_unique<TwoPortDevice>(), scheduler_, std::vector<BusPort*>{&port1_, &port2_},
        NodeSettings{{PortSettings{3, 4}, PortSettings{4, 4}}, state_dir_, {}, {}});
    node_->Start();
    can1_.Clear();
    can2_.Clear();
  }
  TwoPortDevice& device() { return static_cast<TwoPortDevice&>(node_->device()); }
  std::filesystem::path state_dir_;
  SimulatedScheduler scheduler_;
  LoopbackBus bus1_, bus2_;
  LoopbackPort& port1_ = bus1_.Attach("node");
  LoopbackPort& port2_ = bus2_.Attach("node");
  canfleet::test::BusProbe can1_{bus1_, "master1"};
  canfleet::test::BusProbe can2_{bus2_, "master2"};
  std::unique_ptr<DeviceNode> node_;
};

TEST_F(TwoPortTest, ApplicationObjectsAreOneObjectAndRulesApplyOnBothPorts) {
  EXPECT_EQ(node_->PortCount(), 2u);
  EXPECT_TRUE(node_->od(1).IsBorrowed(0x2000));
  EXPECT_EQ(node_->od(1).Find(0x2000, 0), node_->od(0).Find(0x2000, 0));  // one object, not a copy
  EXPECT_FALSE(node_->od(1).IsBorrowed(0x1017));                          // communication: per port
  can2_.Send("604#2B00200008000000");                                     // port 2, node 4: 2000h = 8
  EXPECT_EQ(can2_.Next(), "584#6000200000000000");
  EXPECT_EQ(device().changes, 1);
  can1_.Send("603#4000200000000000");
  EXPECT_EQ(can1_.Next(), "583#4B00200008000000");
  can2_.Send("604#2B00200007000000");  // odd: the device's validator refuses on either port
  EXPECT_EQ(can2_.Next(), "584#8000200030000906");
  device().measured.Set(0x5A);  // a block writes the device's object
  can2_.Send("604#4000600000000000");
  EXPECT_EQ(can2_.Next(), "584#4F0060005A000000");
}

TEST_F(TwoPortTest, EachPortHasItsOwnNmtState) {
  can1_.Send("000#0203");  // stop port 1's node
  EXPECT_EQ(node_->stack(0).State(), NmtState::kStopped);
  EXPECT_EQ(node_->stack(1).State(), NmtState::kPreOperational);
  can2_.Send("604#4000100000000000");
  EXPECT_EQ(can2_.Next().substr(0, 6), "584#43");
}

// A reset node on one port restores that port's communication objects; the device's shared
// objects are not that port's to reset (they belong to the device, port 1's dictionary).
TEST_F(TwoPortTest, AResetOfPortTwoLeavesTheSharedObjects) {
  can2_.Send("604#2B00200008000000");
  EXPECT_EQ(can2_.Next(), "584#6000200000000000");
  can2_.Send("000#8104");  // reset node, port 2
  can2_.Send("604#4000200000000000");
  can2_.Take();
  can1_.Send("603#4000200000000000");
  EXPECT_EQ(can1_.Next(), "583#4B00200008000000");
}

// UMAX181001 §3.2.10/§3.2.11: "save" or "load" on either bus applies to the device. A power-on
// restores what was stored, whichever port stored it, and the second port's power-on never puts
// its defaults over the first port's restored values.
class TwoPortStorageTest : public TwoPortTest {
 protected:
  TwoPortStorageTest() : TwoPortTest(MakeDir()) {}
  ~TwoPortStorageTest() override { std::filesystem::remove_all(state_dir_); }
  static std::filesystem::path MakeDir() {
    auto dir = std::filesystem::temp_directory_path() /
               ("canfleet-twoport-" + std::to_string(::getpid()) + "-" +
                ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir);
    return dir;
  }
  std::string Read2000(canfleet::test::BusProbe& can, const char* request) {
    can.Send(request);
    return can.Next();
  }
};

TEST_F(TwoPortStorageTest, StoredOnPortOneSurvivesPowerOn) {
  can1_.Send("603#2B00200008000000");
  EXPECT_EQ(can1_.Next(), "583#6000200000000000");
  can1_.Send("603#2310100173617665");  // 1010h sub 1 "save"
  EXPECT_EQ(can1_.Next(), "583#6010100100000000");
  Boot();
  EXPECT_EQ(Read2000(can2_, "604#4000200000000000"), "584#4B00200008000000");
  EXPECT_EQ(Read2000(can1_, "603#4000200000000000"), "583#4B00200008000000");
}

TEST_F(TwoPortStorageTest, StoredOnPortTwoCoversTheSharedObjects) {
  can2_.Send("604#2B0020000A000000");
  EXPECT_EQ(can2_.Next(), "584#6000200000000000");
  can2_.Send("604#2310100473617665");  // 1010h sub 4 "save" manufacturer objects, port 2
  EXPECT_EQ(can2_.Next(), "584#6010100400000000");
  Boot();
  EXPECT_EQ(Read2000(can1_, "603#4000200000000000"), "583#4B0020000A000000");
}

TEST_F(TwoPortStorageTest, RestoreOnPortTwoBringsBackTheDefaultsAfterAReset) {
  can1_.Send("603#2B0020000C000000");
  EXPECT_EQ(can1_.Next(), "583#6000200000000000");
  can1_.Send("603#2310100173617665");
  EXPECT_EQ(can1_.Next(), "583#6010100100000000");
  can2_.Send("604#231110016C6F6164");  // 1011h sub 1 "load", port 2
  EXPECT_EQ(can2_.Next(), "584#6011100100000000");
  Boot();
  EXPECT_EQ(Read2000(can1_, "603#4000200000000000"), "583#4B00200002000000");
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

namespace canfleet::devices {
namespace {

// A device that uses the port hooks of the framework (issue 15 point 7): it counts every frame it
// sees before the stack, mutes the stack while "asleep" and speaks for itself.
class HookDevice final : public Device {
 public:
  std::string_view Name() const override { return "hooks"; }
  void Build(std::size_t, canopen::ObjectDictionary& od) override {
    canopen::AddStandardObjects(od, {});
    od.Find(0x1017, 0)->default_value = canopen::EncodeLe<std::uint16_t>(100);  // heartbeat every 100 ms
  }
  void Attach(DeviceContext& context) override {
    port = context.ports.at(0);
    port->ObserveFrames([this](const CanFrame&) { ++seen; });
  }
  DevicePort* port = nullptr;
  int seen = 0;
};

TEST(DevicePortTest, ADeviceSeesFramesFirstMutesItsStackAndSendsItself) {
  SimulatedScheduler scheduler;
  LoopbackBus bus;
  LoopbackPort& raw = bus.Attach("node");
  canfleet::test::BusProbe can{bus, "master"};
  DeviceNode node(std::make_unique<HookDevice>(), scheduler, {&raw},
                  NodeSettings{{PortSettings{5, 4}}, {}, {}, {}});
  auto& device = static_cast<HookDevice&>(node.device());
  node.Start();
  EXPECT_EQ(can.Next(), "705#00");  // boot-up
  can.Send("000#0105");             // NMT start node 5: seen by the device, then by the stack
  EXPECT_EQ(device.seen, 1);
  EXPECT_EQ(node.stack().State(), NmtState::kOperational);
  scheduler.Advance(100ms);
  EXPECT_EQ(can.Next(), "705#05");  // heartbeat, operational
  device.port->SetMuted(true);      // asleep: the stack's heartbeats stay off the bus
  scheduler.Advance(300ms);
  EXPECT_EQ(can.Count(), 0u);
  EXPECT_TRUE(
      device.port->SendFromDevice(CanFrame::Data(0x000, {0x01, 0x00})));  // the device's own NMT Start
  EXPECT_EQ(can.Next(), "000#0100");
  device.port->SetMuted(false);
  scheduler.Advance(100ms);
  EXPECT_EQ(can.Next(), "705#05");
}

}  // namespace
}  // namespace canfleet::devices

namespace canfleet::devices {
namespace {

// REAL32 objects (the family's constants 5010h, supply voltage 5020h, current-loop gains 2382h)
// are numbers to the blocks; integers take numbers rounded and saturated, never wrapped.
TEST(OdRefTest, RealsAndIntegersAsNumbers) {
  canopen::ObjectDictionary od;
  od.AddVar(0x5020, "Power Supply FV", canopen::DataType::kReal32, canopen::Access::kRo,
            canopen::EncodeLe(24.5f));
  od.AddVar(0x2460, "PID Output FV", canopen::DataType::kInteger16, canopen::Access::kRo,
            canopen::EncodeLe<std::int16_t>(0));
  od.AddVar(0x2000, "Level", canopen::DataType::kUnsigned8, canopen::Access::kRo, {0});
  const OdRef supply(od, 0x5020, 0);
  const OdRef pid(od, 0x2460, 0);
  const OdRef level(od, 0x2000, 0);
  EXPECT_TRUE(supply.IsReal());
  EXPECT_DOUBLE_EQ(supply.GetNumber(), 24.5);
  EXPECT_EQ(supply.Get(), 25);  // rounded
  EXPECT_TRUE(supply.SetNumber(12.25));
  EXPECT_DOUBLE_EQ(supply.GetNumber(), 12.25);
  EXPECT_FALSE(supply.SetNumber(12.25));  // unchanged: no write, no listener
  EXPECT_TRUE(supply.Set(7));
  EXPECT_DOUBLE_EQ(supply.GetNumber(), 7.0);
  EXPECT_TRUE(pid.SetNumber(999.6));
  EXPECT_EQ(pid.Get(), 1000);
  EXPECT_TRUE(pid.SetNumber(-1e9));
  EXPECT_EQ(pid.Get(), -32768);
  EXPECT_TRUE(level.SetNumber(300));
  EXPECT_EQ(level.Get(), 255);
  EXPECT_TRUE(level.SetNumber(-4));
  EXPECT_EQ(level.Get(), 0);
  EXPECT_FALSE(level.SetNumber(std::nan("")));
  od.AddVar(0x1008, "Name", canopen::DataType::kVisibleString, canopen::Access::kConst,
            canopen::ToBytes("x"));
  EXPECT_THROW(OdRef(od, 0x1008, 0), std::logic_error);
}

}  // namespace
}  // namespace canfleet::devices
