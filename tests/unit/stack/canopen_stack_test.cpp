// The composed CiA 301 slave, end to end over a loopback bus on simulated time: NMT gating of
// services (CiA 301 §7.3.2.2 table 51), the reset sequence (§7.3.2.2.1 figure 48), error
// behaviour 1029h (§7.5.2.32), bus-off handling, LSS node-ID change (CiA 305 §3.8.2) and stored
// parameters (§7.5.2.13). Frames are written as candump text: "605#40..." is the master's request.
#include "node/canopen/stack/canopen_stack.hpp"

#include <gtest/gtest.h>

#include <filesystem>

#include "node/canopen/stack/standard_objects.hpp"
#include "tests/support/bus_probe.hpp"

namespace canfleet::canopen {
namespace {

using namespace std::chrono_literals;

void BuildOd(ObjectDictionary& od) {
  StandardObjectsOptions o;
  o.device_type = 0x00000191;
  o.identity = {0x55, 0xAA020502, 0x00010002, 0x12345678};
  AddStandardObjects(od, o);
  od.AddVar(0x2000, "Application parameter", DataType::kUnsigned16, Access::kRw, EncodeLe<std::uint16_t>(7));
}

class StackTest : public ::testing::Test {
 protected:
  explicit StackTest(std::uint8_t node_id = 5, std::filesystem::path state_dir = {}) {
    BuildOd(od);
    StackOptions options;
    options.node_id = node_id;
    options.state_dir = std::move(state_dir);
    stack = std::make_unique<CanopenStack>(od, node_port, scheduler, options);
  }

  SimulatedScheduler scheduler;
  LoopbackBus bus;
  LoopbackPort& node_port = bus.Attach("node");
  test::BusProbe master{bus, "master"};
  ObjectDictionary od;
  std::unique_ptr<CanopenStack> stack;
};

TEST_F(StackTest, BootsWithBootUpMessageIntoPreOperational) {
  stack->Start();
  EXPECT_EQ(master.Take(), std::vector<std::string>{"705#00"});  // §7.2.8.3.3 boot-up: 700h+id, 00h
  EXPECT_EQ(stack->State(), NmtState::kPreOperational);
}

TEST_F(StackTest, SdoServesInPreOperationalAndOperationalButNotInStopped) {
  stack->Start();
  master.Clear();
  master.Send("605#4000100000000000");
  EXPECT_EQ(master.Next(), "585#4300100091010000");
  master.Send("000#0205");  // stop node 5
  master.Send("605#4000100000000000");
  EXPECT_EQ(master.Count(), 0u);
  master.Send("000#0100");  // start all nodes
  master.Send("605#4000100000000000");
  EXPECT_EQ(master.Next(), "585#4300100091010000");
}

TEST_F(StackTest, HeartbeatConfiguredBySdoCarriesTheNmtState) {
  stack->Start();
  master.Clear();
  master.Send("605#2B17100064000000");  // 1017h = 100 ms
  EXPECT_EQ(master.Next(), "585#6017100000000000");
  scheduler.Advance(100ms);
  EXPECT_EQ(master.Next(), "705#7F");
  master.Send("000#0105");
  scheduler.Advance(100ms);
  EXPECT_EQ(master.Next(), "705#05");
  master.Send("000#0205");
  scheduler.Advance(100ms);
  EXPECT_EQ(master.Next(), "705#04");
}

TEST_F(StackTest, ResetNodeRestoresEveryParameterAndBootsAgain) {
  stack->Start();
  master.Send("605#2B17100064000000");
  master.Send("605#2B00200009000000");  // 2000h = 9
  master.Clear();
  master.Send("000#8105");
  EXPECT_EQ(master.Next(), "705#00");
  EXPECT_EQ(od.GetUnsigned(0x1017, 0), 0u);
  EXPECT_EQ(od.GetUnsigned(0x2000, 0), 7u);
}

TEST_F(StackTest, ResetCommunicationRestoresOnlyTheCommunicationArea) {
  stack->Start();
  master.Send("605#2B17100064000000");
  master.Send("605#2B00200009000000");
  master.Clear();
  master.Send("000#8200");  // broadcast
  EXPECT_EQ(master.Next(), "705#00");
  EXPECT_EQ(od.GetUnsigned(0x1017, 0), 0u);
  EXPECT_EQ(od.GetUnsigned(0x2000, 0), 9u);
}

// Heartbeat consumer timeout → EMCY 8130h, 1003h entry, and 1029h sub1 = 0 → pre-operational.
TEST_F(StackTest, HeartbeatLossRaisesEmcyAndAppliesErrorBehaviour) {
  stack->Start();
  master.Send("605#2316100164000300");  // 1016h.1 = node 3, 100 ms
  master.Send("000#0105");
  master.Clear();
  master.Send("703#05");  // monitoring starts with the first heartbeat
  scheduler.Advance(99ms);
  EXPECT_EQ(master.Count(), 0u);
  scheduler.Advance(1ms);
  EXPECT_EQ(master.Next(), "085#3081110300000000");
  EXPECT_EQ(stack->State(), NmtState::kPreOperational);
  EXPECT_EQ(od.GetUnsigned(0x1003, 1), 0x00038130u);
  EXPECT_EQ(od.GetUnsigned(0x1001, 0) & 0x11, 0x11u);
}

TEST_F(StackTest, ErrorBehaviourTwoStopsTheNodeAndOneLeavesItAlone) {
  stack->Start();
  master.Send("605#2F29100102000000");  // 1029h.1 = 2 (stopped)
  master.Send("000#0105");
  node_port.SetControllerState({ControllerState::kBusOff, 256, 0});
  EXPECT_EQ(stack->State(), NmtState::kStopped);

  node_port.SetControllerState({ControllerState::kErrorActive, 0, 0});
  master.Send("000#0105");
  master.Send("605#2F29100101000000");  // 1029h.1 = 1 (no change)
  node_port.SetControllerState({ControllerState::kBusOff, 256, 0});
  EXPECT_EQ(stack->State(), NmtState::kOperational);
}

TEST_F(StackTest, BusOffIsRecordedIn1003hAndClearsOnRecovery) {
  stack->Start();
  master.Send("000#0105");
  node_port.SetControllerState({ControllerState::kBusOff, 256, 0});
  EXPECT_EQ(stack->State(), NmtState::kPreOperational);  // 1029h.1 default 0
  EXPECT_EQ(od.GetUnsigned(0x1003, 1) & 0xFFFF, 0x8140u);
  EXPECT_EQ(stack->Controller().state, ControllerState::kBusOff);
  node_port.SetControllerState({ControllerState::kErrorActive, 0, 0});
  EXPECT_EQ(stack->emcy().ActiveCount(), 0u);
}

// The 8140h EMCY raised at bus-off could not be sent then: it is the first frame after recovery,
// then the error reset; 1003h keeps 00008140h as history for the master to read afterwards.
TEST_F(StackTest, BusOffEmcyIsSentAfterRecoveryAndStaysIn1003h) {
  stack->Start();
  master.Send("000#0105");
  master.Clear();
  node_port.SetControllerState({ControllerState::kBusOff, 256, 0});
  scheduler.Advance(std::chrono::milliseconds(100));
  node_port.SetControllerState({ControllerState::kErrorActive, 0, 0});
  scheduler.Advance(std::chrono::milliseconds(10));
  std::vector<std::string> emcy;
  for (const auto& frame : master.Take())
    if (frame.rfind("085#", 0) == 0) emcy.push_back(frame);
  EXPECT_EQ(emcy, (std::vector<std::string>{"085#4081110000000000", "085#0000000000000000"}));
  EXPECT_EQ(od.GetUnsigned(0x1003, 0), 1u);
  EXPECT_EQ(od.GetUnsigned(0x1003, 1), 0x00008140u);
  EXPECT_EQ(od.GetUnsigned(0x1001, 0), 0u);
}

// CiA 305: configure node-ID while in configuration mode, then switch back to waiting: the node
// resets communication with the new ID, and its predefined COB-IDs follow.
TEST_F(StackTest, LssNodeIdChangeRebootsWithTheNewId) {
  stack->Start();
  master.Clear();
  master.Send("7E5#0401000000000000");
  master.Send("7E5#1120000000000000");
  EXPECT_EQ(master.Next(), "7E4#1100000000000000");
  master.Send("7E5#0400000000000000");
  EXPECT_EQ(master.Next(), "720#00");
  EXPECT_EQ(stack->NodeId(), 0x20);
  master.Send("620#4000100000000000");
  EXPECT_EQ(master.Next(), "5A0#4300100091010000");
  EXPECT_EQ(od.GetUnsigned(0x1800, 1) & 0x7FF, 0x1A0u);
}

class UnconfiguredStackTest : public StackTest {
 protected:
  UnconfiguredStackTest() : StackTest(kUnconfiguredNodeId) {}
};

TEST_F(UnconfiguredStackTest, AnUnconfiguredNodeIsSilentUntilLssGivesItAnId) {
  stack->Start();
  EXPECT_EQ(master.Count(), 0u);
  master.Send("000#0100");
  master.Send("67F#4000100000000000");
  EXPECT_EQ(master.Count(), 0u);
  master.Send("7E5#5E00000000000000");  // inquire node-ID: not in configuration mode → no answer
  EXPECT_EQ(master.Count(), 0u);
  master.Send("7E5#0401000000000000");
  master.Send("7E5#5E00000000000000");
  EXPECT_EQ(master.Next(), "7E4#5EFF000000000000");
  master.Send("7E5#1107000000000000");
  EXPECT_EQ(master.Next(), "7E4#1100000000000000");
  master.Send("7E5#0400000000000000");
  EXPECT_EQ(master.Next(), "707#00");
}

class StoredStackTest : public ::testing::Test {
 protected:
  std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) /
                              ("canfleet-stack-" + std::to_string(::getpid()) + "-" +
                               ::testing::UnitTest::GetInstance()->current_test_info()->name());
  void SetUp() override { std::filesystem::remove_all(dir); }
  StackOptions Options() const {
    StackOptions options;
    options.node_id = 5;
    options.state_dir = dir;
    return options;
  }
  void TearDown() override { std::filesystem::remove_all(dir); }
};

// 1010h sub1 "save" (CiA 301 §7.5.2.13), then a restart of the process (a new OD and stack on the
// same state directory) brings the values back.
TEST_F(StoredStackTest, SavedParametersSurviveARestart) {
  {
    SimulatedScheduler scheduler;
    LoopbackBus bus;
    auto& port = bus.Attach("node");
    test::BusProbe master(bus);
    ObjectDictionary od;
    BuildOd(od);
    CanopenStack stack(od, port, scheduler, Options());
    stack.Start();
    master.Send("605#2B170000FA000000");  // wrong index on purpose: 1700h does not exist
    master.Send("605#2B171000FA000000");  // 1017h = 250
    master.Send("605#2B0020002A000000");  // 2000h = 42
    master.Clear();
    master.Send("605#2310100173617665");  // 1010h.1 = "save"
    EXPECT_EQ(master.Next(), "585#6010100100000000");
  }
  SimulatedScheduler scheduler;
  LoopbackBus bus;
  auto& port = bus.Attach("node");
  ObjectDictionary od;
  BuildOd(od);
  CanopenStack stack(od, port, scheduler, Options());
  stack.Start();
  EXPECT_EQ(od.GetUnsigned(0x1017, 0), 250u);
  EXPECT_EQ(od.GetUnsigned(0x2000, 0), 42u);
}

}  // namespace
}  // namespace canfleet::canopen
