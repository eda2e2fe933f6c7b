// NMT slave, CiA 301 v4.2: module control protocol §7.2.8.3.1 (COB-ID 000h, DLC 2, CS + node-ID),
// boot-up protocol §7.2.8.3.3 (700h+id [00]), NMT state machine §7.3.2 (figure 48).
#include "node/canopen/nmt/nmt_slave.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <tuple>
#include <vector>

#include "bus/loopback_bus.hpp"
#include "tests/support/bus_probe.hpp"

namespace canfleet::canopen {
namespace {

using test::BusProbe;

constexpr std::uint8_t kNodeId = 0x05;

class NmtSlaveTest : public ::testing::Test {
 protected:
  NmtSlaveTest() {
    port.OnReceive([this](const CanFrame& frame, BusTime) { consumed.push_back(nmt.OnFrame(frame)); });
  }

  NmtSlave::Callbacks MakeCallbacks() {
    return {[this] {
              ++reset_node;
              state_in_reset = nmt.State();
              nmt.Boot();
            },
            [this] {
              ++reset_communication;
              state_in_reset = nmt.State();
              nmt.Boot();
            },
            [this](NmtState s) { changes.push_back(s); }};
  }

  /// Boots and drives the slave into `state` with NMT commands, then forgets the history.
  void BootInto(NmtState state) {
    nmt.Boot();
    if (state == NmtState::kOperational) master.Send("000#0105");
    if (state == NmtState::kStopped) master.Send("000#0205");
    ASSERT_EQ(nmt.State(), state);
    master.Clear();
    changes.clear();
    consumed.clear();
  }

  LoopbackBus bus;
  BusProbe master{bus, "master"};
  LoopbackPort& port = bus.Attach("node");
  std::vector<NmtState> changes;
  std::vector<bool> consumed;
  int reset_node = 0;
  int reset_communication = 0;
  NmtState state_in_reset = NmtState::kOperational;
  NmtSlave nmt{port, kNodeId, MakeCallbacks()};
};

// §7.2.8.3.3: Initialising → Pre-operational, announced by the boot-up message 700h+id, DLC 1, 00h.
TEST_F(NmtSlaveTest, BootSendsBootUpAndEntersPreOperational) {
  EXPECT_EQ(nmt.State(), NmtState::kInitialising);
  nmt.Boot();
  EXPECT_EQ(master.Take(), std::vector<std::string>{"705#00"});
  EXPECT_EQ(nmt.State(), NmtState::kPreOperational);
  EXPECT_EQ(changes, std::vector<NmtState>{NmtState::kPreOperational});
}

// Devices with "start in operational" (5555h in the device digests) boot straight to Operational,
// still sending the boot-up message first.
TEST_F(NmtSlaveTest, BootCanStartOperational) {
  nmt.Boot(true);
  EXPECT_EQ(master.Take(), std::vector<std::string>{"705#00"});
  EXPECT_EQ(nmt.State(), NmtState::kOperational);
  EXPECT_EQ(changes, std::vector<NmtState>{NmtState::kOperational});
}

// CiA 305 §3.4: a slave without a valid node-ID (FFh = unconfigured) stays in Initialising.
TEST_F(NmtSlaveTest, BootWithoutValidNodeIdSendsNothing) {
  for (std::uint8_t id : {std::uint8_t{0}, std::uint8_t{128}, std::uint8_t{0xFF}}) {
    NmtSlave slave(port, id, {});
    slave.Boot();
    EXPECT_EQ(slave.State(), NmtState::kInitialising) << int{id};
  }
  EXPECT_EQ(master.Count(), 0u);
}

// The highest node-ID still fits the 11-bit boot-up COB-ID: 77Fh.
TEST_F(NmtSlaveTest, BootUpUsesTheNodeIdSet) {
  nmt.SetNodeId(127);
  nmt.Boot();
  EXPECT_EQ(master.Next(), "77F#00");
  master.Send("000#017F");
  EXPECT_EQ(nmt.State(), NmtState::kOperational);
  master.Send("000#0205");  // the old ID no longer addresses the node
  EXPECT_EQ(nmt.State(), NmtState::kOperational);
}

TEST_F(NmtSlaveTest, CommandsBeforeBootAreIgnored) {
  master.Send("000#0105");
  master.Send("000#0100");
  master.Send("000#8205");
  EXPECT_EQ(nmt.State(), NmtState::kInitialising);
  EXPECT_EQ(reset_communication, 0);
  EXPECT_TRUE(changes.empty());
  EXPECT_EQ(master.Count(), 0u);
}

// §7.3.2, figure 48: every transition between Pre-operational, Operational and Stopped, both
// addressed to the node and broadcast (node-ID 0).
struct Transition {
  NmtState from;
  std::uint8_t command;
  NmtState to;
};

class NmtTransitionTest : public NmtSlaveTest,
                          public ::testing::WithParamInterface<std::tuple<Transition, bool>> {};

TEST_P(NmtTransitionTest, CommandMovesToTheExpectedState) {
  const auto [t, broadcast] = GetParam();
  BootInto(t.from);
  char frame[16];
  std::snprintf(frame, sizeof frame, "000#%02X%02X", t.command, broadcast ? 0 : kNodeId);
  master.Send(frame);
  EXPECT_EQ(nmt.State(), t.to);
  // A command for the state the node is in changes nothing and notifies nobody.
  if (t.from == t.to) {
    EXPECT_TRUE(changes.empty());
  } else {
    EXPECT_EQ(changes, std::vector<NmtState>{t.to});
  }
  EXPECT_EQ(consumed, std::vector<bool>{true});
  EXPECT_EQ(master.Count(), 0u);  // module control is unconfirmed: no reply
}

std::string Name(NmtState s) {
  switch (s) {
    case NmtState::kPreOperational:
      return "PreOperational";
    case NmtState::kOperational:
      return "Operational";
    case NmtState::kStopped:
      return "Stopped";
    default:
      return "Initialising";
  }
}

std::string Name(std::uint8_t command) {
  char text[8];
  std::snprintf(text, sizeof text, "Cs%02X", command);
  return text;
}

std::string TransitionName(const ::testing::TestParamInfo<std::tuple<Transition, bool>>& info) {
  const auto& [t, broadcast] = info.param;
  return Name(t.from) + "_" + Name(t.command) + "_" + (broadcast ? "Broadcast" : "Addressed");
}

constexpr NmtState kPre = NmtState::kPreOperational;
constexpr NmtState kOp = NmtState::kOperational;
constexpr NmtState kStop = NmtState::kStopped;

INSTANTIATE_TEST_SUITE_P(Figure48, NmtTransitionTest,
                         ::testing::Combine(::testing::Values(Transition{kPre, 0x01, kOp},     // (3)
                                                              Transition{kPre, 0x02, kStop},   // (5)
                                                              Transition{kPre, 0x80, kPre},    //
                                                              Transition{kOp, 0x01, kOp},      //
                                                              Transition{kOp, 0x02, kStop},    // (8)
                                                              Transition{kOp, 0x80, kPre},     // (4)
                                                              Transition{kStop, 0x01, kOp},    // (6)
                                                              Transition{kStop, 0x02, kStop},  //
                                                              Transition{kStop, 0x80, kPre}),  // (7)
                                            ::testing::Bool()),
                         TransitionName);

// §7.3.2: reset node and reset communication are accepted in every state; the node goes through
// Initialising, the stack restores its parameters, and the boot-up message is sent again.
using ResetParam = std::tuple<NmtState, std::uint8_t /*command*/, bool /*broadcast*/>;

std::string ResetName(const ::testing::TestParamInfo<ResetParam>& info) {
  const auto& [from, command, broadcast] = info.param;
  return Name(from) + "_" + Name(command) + "_" + (broadcast ? "Broadcast" : "Addressed");
}

class NmtResetTest : public NmtSlaveTest, public ::testing::WithParamInterface<ResetParam> {};

TEST_P(NmtResetTest, ResetGoesThroughInitialisingAndBootsAgain) {
  const auto [from, command, broadcast] = GetParam();
  BootInto(from);
  char frame[16];
  std::snprintf(frame, sizeof frame, "000#%02X%02X", command, broadcast ? 0 : kNodeId);
  master.Send(frame);
  EXPECT_EQ(reset_node, command == 0x81 ? 1 : 0);
  EXPECT_EQ(reset_communication, command == 0x82 ? 1 : 0);
  EXPECT_EQ(state_in_reset, NmtState::kInitialising);  // services are gated while parameters are restored
  EXPECT_EQ(master.Take(), std::vector<std::string>{"705#00"});
  EXPECT_EQ(nmt.State(), NmtState::kPreOperational);
  EXPECT_EQ(changes, (std::vector<NmtState>{NmtState::kInitialising, NmtState::kPreOperational}));
}

INSTANTIATE_TEST_SUITE_P(Figure48, NmtResetTest,
                         ::testing::Combine(::testing::Values(kPre, kOp, kStop),
                                            ::testing::Values(std::uint8_t{0x81}, std::uint8_t{0x82}),
                                            ::testing::Bool()),
                         ResetName);

// §7.2.8.3.1: byte 1 selects the node; a command for another node leaves this one alone.
TEST_F(NmtSlaveTest, CommandsForOtherNodesAreIgnoredInEveryState) {
  for (NmtState from : {kPre, kOp, kStop}) {
    SCOPED_TRACE(ToString(from));
    BootInto(from);
    for (const char* frame : {"000#0106", "000#0204", "000#8006", "000#817F", "000#8201"})
      master.Send(frame);
    EXPECT_EQ(nmt.State(), from);
    EXPECT_TRUE(changes.empty());
    EXPECT_EQ(reset_node + reset_communication, 0);
    EXPECT_EQ(master.Count(), 0u);
    // NMT frames are consumed even when they address another node: nothing else uses 000h.
    EXPECT_EQ(consumed, std::vector<bool>(5, true));
  }
}

// §7.2.8.3.1: the command has exactly two bytes; frames with another DLC are not NMT commands.
TEST_F(NmtSlaveTest, FramesWithDlcOtherThanTwoAreIgnored) {
  BootInto(kPre);
  for (const char* frame : {"000#", "000#01", "000#010500", "000#0105000000000000", "000#8105AA"})
    master.Send(frame);
  EXPECT_EQ(nmt.State(), kPre);
  EXPECT_TRUE(changes.empty());
  EXPECT_EQ(reset_node, 0);
  EXPECT_EQ(consumed, std::vector<bool>(5, false));
}

// Only a standard data frame on 000h is an NMT command: not a remote frame, not a 29-bit ID 0,
// not 000h + node-ID.
TEST_F(NmtSlaveTest, OtherIdentifiersAndFrameFormatsAreIgnored) {
  BootInto(kPre);
  master.Send("000#R2");
  master.Send("00000000#0105");
  master.Send("005#0105");
  master.Send("705#0105");
  EXPECT_EQ(nmt.State(), kPre);
  EXPECT_EQ(consumed, std::vector<bool>(4, false));
}

// Command specifiers not in §7.2.8.3.1 (e.g. python-canopen's 50h sleep, 60h standby) are ignored.
TEST_F(NmtSlaveTest, UnknownCommandSpecifiersAreIgnoredInEveryState) {
  for (NmtState from : {kPre, kOp, kStop}) {
    SCOPED_TRACE(ToString(from));
    BootInto(from);
    for (const char* frame :
         {"000#0005", "000#0305", "000#0400", "000#5005", "000#6000", "000#7F05", "000#8305", "000#FF00"}) {
      master.Send(frame);
    }
    EXPECT_EQ(nmt.State(), from);
    EXPECT_TRUE(changes.empty());
    EXPECT_EQ(reset_node + reset_communication, 0);
    EXPECT_EQ(master.Count(), 0u);
  }
}

// Local transitions (1029h error behaviour, device logic) notify like NMT commands do.
TEST_F(NmtSlaveTest, SetStateChangesStateLocally) {
  BootInto(kOp);
  nmt.SetState(kPre);
  nmt.SetState(kPre);
  nmt.SetState(kStop);
  nmt.SetState(NmtState::kInitialising);  // not a local transition: resets go through the stack
  nmt.SetState(static_cast<NmtState>(0x42));
  EXPECT_EQ(nmt.State(), kStop);
  EXPECT_EQ(changes, (std::vector<NmtState>{kPre, kStop}));
  EXPECT_EQ(master.Count(), 0u);
}

TEST_F(NmtSlaveTest, SetStateBeforeBootIsIgnored) {
  nmt.SetState(kOp);
  EXPECT_EQ(nmt.State(), NmtState::kInitialising);
  EXPECT_TRUE(changes.empty());
}

// Execute() runs a command locally (LSS "back to waiting" resets communication, CiA 305).
TEST_F(NmtSlaveTest, ExecuteRunsACommandLocally) {
  BootInto(kOp);
  nmt.Execute(NmtCommand::kResetCommunication);
  EXPECT_EQ(reset_communication, 1);
  EXPECT_EQ(master.Take(), std::vector<std::string>{"705#00"});
  EXPECT_EQ(nmt.State(), kPre);
}

// Without reset callbacks there is nothing to restore: the slave boots again by itself,
// remembering whether it starts operational.
TEST_F(NmtSlaveTest, WithoutCallbacksAResetBootsAgainByItself) {
  NmtSlave slave(port, kNodeId, {});
  port.OnReceive([&](const CanFrame& frame, BusTime) { slave.OnFrame(frame); });
  slave.Boot(true);
  master.Send("000#0205");
  EXPECT_EQ(slave.State(), kStop);
  master.Send("000#8100");
  EXPECT_EQ(slave.State(), kOp);
  master.Send("000#8205");
  EXPECT_EQ(slave.State(), kOp);
  EXPECT_EQ(master.Take(), (std::vector<std::string>{"705#00", "705#00", "705#00"}));
}

// The state-change callback may itself change the state (an error reaction): the last one wins
// and every change is reported in order.
TEST_F(NmtSlaveTest, StateChangeCallbackMayChangeStateAgain) {
  std::vector<NmtState> seen;
  NmtSlave* self = nullptr;
  NmtSlave slave(port, kNodeId, {nullptr, nullptr, [&](NmtState s) {
                                   seen.push_back(s);
                                   if (s == kOp) self->SetState(kStop);
                                 }});
  self = &slave;
  port.OnReceive([&](const CanFrame& frame, BusTime) { slave.OnFrame(frame); });
  slave.Boot();
  master.Send("000#0105");
  EXPECT_EQ(slave.State(), kStop);
  EXPECT_EQ(seen, (std::vector<NmtState>{kPre, kOp, kStop}));
}

}  // namespace
}  // namespace canfleet::canopen
