// The composed CiA 301 slave, end to end over a loopback bus on simulated time: NMT gating of
// services (CiA 301 §7.3.2.2 table 51), the reset sequence (§7.3.2.2.1 figure 48), error
// behaviour 1029h (§7.5.2.32), bus-off handling, LSS node-ID change (CiA 305 §3.8.2) and stored
// parameters (§7.5.2.13). Frames are written as candump text: "605#40..." is the master's request.
#include "node/canopen/stack/canopen_stack.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <functional>

#include "node/canopen/stack/standard_objects.hpp"
#include "node/canopen/storage/atomic_file.hpp"
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
// then the error reset, which takes 00008140h out of 1003h: an entry "is immediately removed when
// the error condition has been cleared" and sub 0 is zero in an error-free state (AX020506 §3.1.4).
TEST_F(StackTest, BusOffEmcyIsSentAfterRecoveryAndLeaves1003hAtTheReset) {
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
  EXPECT_EQ(od.GetUnsigned(0x1003, 0), 0u);
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

// A save all killed part-way (storage/store_transaction.hpp) is settled when the stack starts,
// before it applies anything, and the storage hook says so: with its commit record written the
// save is completed, without it the staged files are discarded.
TEST_F(StoredStackTest, AnInterruptedSaveAllIsSettledAndReportedAtStart) {
  auto run = [this](const std::function<void(CanopenStack&, ObjectDictionary&)>& body,
                    std::vector<std::string>* logged = nullptr) {
    SimulatedScheduler scheduler;
    LoopbackBus bus;
    auto& port = bus.Attach("node");
    ObjectDictionary od;
    BuildOd(od);
    StackHooks hooks;
    if (logged) hooks.on_storage_issue = [logged](const std::string& text) { logged->push_back(text); };
    CanopenStack stack(od, port, scheduler, Options(), std::move(hooks));
    stack.Start();
    body(stack, od);
  };
  // A save all of 1017h = 250 and 2000h = 42, turned back into the state a kill just before its
  // renames leaves: every group staged as "<file>.new", the files themselves not there yet.
  auto interrupted_save_all = [&](bool committed) {
    std::filesystem::remove_all(dir);
    run([](CanopenStack& stack, ObjectDictionary& od) {
      od.Write(0x1017, 0, EncodeLe<std::uint16_t>(250), Origin::kDevice);
      od.Write(0x2000, 0, EncodeLe<std::uint16_t>(42), Origin::kDevice);
      ASSERT_EQ(stack.store()->Save(1), SdoAbort::kNone);
    });
    CommitRecord record{"save all", {}};
    for (const auto& group : ParameterGroups()) {
      std::filesystem::rename(dir / group.file_name, StagedPathFor(dir / group.file_name));
      record.actions.push_back({FileAction::kReplace, group.file_name});
    }
    if (committed) {
      ASSERT_FALSE(WriteFileAtomically(dir / kCommitRecordName, EncodeCommitRecord(record)));
    }
  };

  interrupted_save_all(true);
  std::vector<std::string> logged;
  run(
      [](CanopenStack&, ObjectDictionary& od) {
        EXPECT_EQ(od.GetUnsigned(0x1017, 0), 250u);
        EXPECT_EQ(od.GetUnsigned(0x2000, 0), 42u);
      },
      &logged);
  ASSERT_EQ(logged.size(), 1u);
  EXPECT_NE(logged[0].find("completed an interrupted save all"), std::string::npos) << logged[0];

  interrupted_save_all(false);
  logged.clear();
  run(
      [](CanopenStack&, ObjectDictionary& od) {
        EXPECT_EQ(od.GetUnsigned(0x1017, 0), 0u);
        EXPECT_EQ(od.GetUnsigned(0x2000, 0), 7u);
      },
      &logged);
  ASSERT_EQ(logged.size(), 1u);
  EXPECT_NE(logged[0].find("discarded an unfinished save all"), std::string::npos) << logged[0];
}

// An error frame (what a port at another bit rate than its bus receives instead of traffic,
// orchestrator/broker/README.md "Bit rate") carries an identifier but is no message: an error
// frame on 000h is no NMT command, one on 7E5h no LSS request.
TEST_F(StackTest, ErrorFramesAreNoMessages) {
  stack->Start();
  master.Clear();
  CanFrame stop = test::Frame("000#0205");
  stop.flags |= CanFrame::kError;
  master.Send(stop);
  CanFrame sdo = test::Frame("605#4000100000000000");
  sdo.flags |= CanFrame::kError;
  master.Send(sdo);
  EXPECT_EQ(stack->State(), NmtState::kPreOperational);
  EXPECT_EQ(master.Count(), 0u);
}

// A device's bit-rate object (the Axiomatic 5B50h "Change Baud Rate", UMAX020411A §3.4.110, a
// CiA 305 table-0 index): StackOptions::bit_rate_object.
class BitRateObjectTest : public StoredStackTest {
 protected:
  static void BuildWithBitRateObject(ObjectDictionary& od) {
    BuildOd(od);
    od.AddVar(0x5B50, "Change Baud Rate", DataType::kUnsigned8, Access::kRw, EncodeLe<std::uint8_t>(4));
  }
  StackOptions WithObject() const {
    StackOptions options = Options();
    options.bit_timing_index = 4;  // the factory's 125 kbit/s
    options.bit_rate_object = BitRateObject{0x5B50, 0};
    return options;
  }
  StackHooks Recording() {
    StackHooks hooks;
    hooks.on_bit_timing = [this](std::uint8_t index) { switches.push_back(index); };
    return hooks;
  }
  std::vector<std::uint8_t> switches;
};

// Written alone, 5B50h changes nothing, not even at the next reset: the reset restores the
// manufacturer area to its stored values (the manuals' 1010h: unsaved changes are lost). Stored
// (1010h), it is the bit rate from the next reset on (NMT reset node), with on_bit_timing; and
// after a restart of the process (power-on) too.
TEST_F(BitRateObjectTest, AStoredValueTakesEffectAtTheNextResetAndAfterPowerOn) {
  {
    SimulatedScheduler scheduler;
    LoopbackBus bus;
    auto& port = bus.Attach("node");
    test::BusProbe master(bus);
    ObjectDictionary od;
    BuildWithBitRateObject(od);
    CanopenStack stack(od, port, scheduler, WithObject(), Recording());
    stack.Start();
    EXPECT_TRUE(switches.empty());
    EXPECT_EQ(od.GetUnsigned(0x5B50, 0), 4u);  // the active index
    master.Clear();
    master.Send("605#2F505B0003000000");  // 5B50h = 3 (250 kbit/s)
    EXPECT_EQ(master.Next(), "585#60505B0000000000");
    EXPECT_TRUE(switches.empty());  // not before a reset
    master.Send("000#8105");        // NMT reset node
    EXPECT_TRUE(switches.empty());  // not stored: lost
    EXPECT_EQ(od.GetUnsigned(0x5B50, 0), 4u);

    master.Send("605#2F505B0003000000");
    master.Send("605#2310100173617665");  // 1010h.1 = "save"
    master.Clear();
    master.Send("000#8105");
    EXPECT_EQ(switches, (std::vector<std::uint8_t>{3}));
    EXPECT_EQ(stack.BitTimingIndex(), 3u);
    EXPECT_EQ(stack.lss().ActiveBitTimingIndex(), 3u);
    EXPECT_EQ(master.Next(), "705#00");  // boots again (at the new rate)
    master.Send("000#8105");
    EXPECT_EQ(switches.size(), 1u);  // already at 3
  }
  switches.clear();
  SimulatedScheduler scheduler;
  LoopbackBus bus;
  auto& port = bus.Attach("node");
  ObjectDictionary od;
  BuildWithBitRateObject(od);
  CanopenStack stack(od, port, scheduler, WithObject(), Recording());
  stack.Start();
  EXPECT_EQ(switches, (std::vector<std::uint8_t>{3}));
  EXPECT_EQ(od.GetUnsigned(0x5B50, 0), 3u);
}

// Only CiA 305 table-0 indexes are bit rates: 5 is reserved (UMAX020411A Table 32), 9 and above
// are none (06090030h invalid value).
TEST_F(BitRateObjectTest, AReservedIndexIsRefused) {
  SimulatedScheduler scheduler;
  LoopbackBus bus;
  auto& port = bus.Attach("node");
  test::BusProbe master(bus);
  ObjectDictionary od;
  BuildWithBitRateObject(od);
  CanopenStack stack(od, port, scheduler, WithObject(), Recording());
  stack.Start();
  master.Clear();
  master.Send("605#2F505B0005000000");
  EXPECT_EQ(master.Next(), "585#80505B0030000906");
  master.Send("605#2F505B0009000000");
  EXPECT_EQ(master.Next(), "585#80505B0030000906");
  master.Send("605#2F505B0008000000");
  EXPECT_EQ(master.Next(), "585#60505B0000000000");
}

// CiA 305 §8.3.2 "activate bit timing": the port switches after the first delay, and the
// bit-rate object follows (its default too), so a later NMT reset keeps the activated rate
// (only a power-off loses it unless LSS stored it).
TEST_F(BitRateObjectTest, LssActivationIsTheObjectsNewValueAndSurvivesAReset) {
  SimulatedScheduler scheduler;
  LoopbackBus bus;
  auto& port = bus.Attach("node");
  test::BusProbe master(bus);
  ObjectDictionary od;
  BuildWithBitRateObject(od);
  CanopenStack stack(od, port, scheduler, WithObject(), Recording());
  stack.Start();
  master.Clear();
  master.Send("7E5#0401000000000000");  // switch state global: configuration
  master.Send("7E5#1300020000000000");  // configure bit timing: table 0, index 2 (500 kbit/s)
  EXPECT_EQ(master.Next(), "7E4#1300000000000000");
  master.Send("7E5#150A000000000000");  // activate bit timing, 10 ms switch delay
  EXPECT_TRUE(switches.empty());
  scheduler.Advance(10ms);
  EXPECT_EQ(switches, (std::vector<std::uint8_t>{2}));
  EXPECT_EQ(od.GetUnsigned(0x5B50, 0), 2u);
  scheduler.Advance(10ms);
  master.Send("000#8105");
  EXPECT_EQ(switches.size(), 1u);
  EXPECT_EQ(stack.BitTimingIndex(), 2u);
  EXPECT_EQ(od.GetUnsigned(0x5B50, 0), 2u);
}

// A node commissioned for its bus (node/process/bit_rate_commissioning.hpp) adopts its rate before
// power-on: no switch, the object and LSS report it.
TEST_F(BitRateObjectTest, AdoptedBitTimingIsTheObjectsValue) {
  SimulatedScheduler scheduler;
  LoopbackBus bus;
  auto& port = bus.Attach("node");
  ObjectDictionary od;
  BuildWithBitRateObject(od);
  CanopenStack stack(od, port, scheduler, WithObject(), Recording());
  stack.AdoptBitTiming(2);
  stack.Start();
  EXPECT_TRUE(switches.empty());
  EXPECT_EQ(od.GetUnsigned(0x5B50, 0), 2u);
  EXPECT_EQ(stack.lss().ActiveBitTimingIndex(), 2u);
  EXPECT_EQ(stack.lss().PendingBitTimingIndex(), 2u);
}

}  // namespace
}  // namespace canfleet::canopen

namespace canfleet::canopen {
namespace {

bool Has(const std::vector<std::uint32_t>& ids, std::uint32_t id) {
  return std::find(ids.begin(), ids.end(), id) != ids.end();
}

// The acceptance filter a node reports in virtual time (orchestrator/broker/README.md "Virtual
// time"): the identifiers its services take (CiA 301 §7.3.2.2: NMT 000h, SDO 600h + ID, node
// guarding 700h + ID; CiA 305: LSS 7E5h), following its configuration: a heartbeat consumer
// configured by SDO (1016h) adds the producer's 700h + ID.
TEST_F(StackTest, ListensToTheIdentifiersOfItsServicesAndFollowsItsConfiguration) {
  stack->Start();
  std::vector<std::uint32_t> ids = stack->ListenedIds();
  EXPECT_TRUE(std::is_sorted(ids.begin(), ids.end()));
  for (std::uint32_t id : {0x000u, 0x605u, 0x705u, 0x7E5u})
    EXPECT_TRUE(Has(ids, id)) << std::hex << id;
  EXPECT_FALSE(Has(ids, 0x703));
  EXPECT_FALSE(Has(ids, 0x185)) << "a TPDO of another node is nothing to this one";
  master.Send("605#2316100164000300");  // 1016h.1 = node 3, 100 ms
  EXPECT_TRUE(Has(stack->ListenedIds(), 0x703));
}

// CiA 305: a node without a node-ID runs LSS only, so it listens to LSS only.
TEST_F(UnconfiguredStackTest, AnUnconfiguredNodeListensToLssOnly) {
  stack->Start();
  EXPECT_EQ(stack->ListenedIds(), (std::vector<std::uint32_t>{0x7E5}));
}

}  // namespace
}  // namespace canfleet::canopen
