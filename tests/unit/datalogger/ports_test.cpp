// The data logger's two CAN ports (UMAX181001 §1.1, §3: "2 CAN interfaces which share
// manufacturer-specific objects but have separate Communication Objects"; §3.2.7-3.2.8 storage on
// either bus; §3.4.78 5555h per port) and the policies of README "Two ports".

#include "node/devices/datalogger_tc_analog/datalogger_objects.hpp"
#include "tests/unit/datalogger/datalogger_fixture.hpp"

namespace canfleet::devices::test {
namespace {

using namespace datalogger;
using canopen::NmtState;

class PortsTest : public DataLoggerTest {
 protected:
  PortsTest() { ConfigureTcLimitsAway(); }
};

// §3: separate communication objects: each port has its own node-ID (CAN1 node 5, CAN2 node 6),
// its own COB-IDs and NMT state, and answers SDO only on its own bus.
TEST_F(PortsTest, SeparateNodeIdsAndCommunicationObjects) {
  EXPECT_EQ(Read(0, 0x1000, 0), 0xE0030194);
  EXPECT_EQ(Read(1, 0x1000, 0), 0xE0030194);
  EXPECT_EQ(Read(0, 0x1800, 1), 0x40000185);
  EXPECT_EQ(Read(1, 0x1800, 1), 0x40000186);
  Write(1, 0x1017, 0, 100, 2);  // heartbeat on CAN2 only
  EXPECT_EQ(Read(0, 0x1017, 0), 0);
  Send(0, SdoRead(kNode2, 0x1000, 0));  // node 6 is not on CAN1
  Advance(100ms);
  EXPECT_TRUE(Frames(0).empty());
  EXPECT_EQ(Frames(1), std::vector<std::string>{"706#7F"});
}

// One port stopped while the other transmits: NMT stop on CAN1 silences CAN1's TPDOs only.
TEST_F(PortsTest, OnePortStoppedWhileTheOtherTransmits) {
  StartBoth();
  Advance(100ms);
  EXPECT_EQ(Frames(0, "185#").size(), 1u);
  EXPECT_EQ(Frames(1, "186#").size(), 1u);
  Send(0, "000#0205");  // stop node 5 on CAN1
  EXPECT_EQ(stack(0).State(), NmtState::kStopped);
  EXPECT_EQ(stack(1).State(), NmtState::kOperational);
  SetNumber("IN1.voltage_mV", 3000);
  Advance(300ms);
  EXPECT_TRUE(Frames(0).empty());
  const auto tpdo1 = Frames(1, "186#");
  ASSERT_EQ(tpdo1.size(), 3u);
  EXPECT_EQ(tpdo1.back(), "186#B80BC409C409C409");  // the shared 7100h as CAN2 maps it
}

// §3.4.78: 5555h sub 1 is CAN1's and sub 2 CAN2's "Start in Operational"; either bus can set
// both (shared object). After a save and a power-on only CAN2 starts operational.
TEST_F(DataLoggerStorageTest, StartInOperationalPerPort) {
  Write(0, kStartOperational, 2, 1, 1);             // written on CAN1, for CAN2
  Write(1, 0x1010, 1, canopen::kSaveSignature, 4);  // "save" on CAN2
  Boot();
  EXPECT_EQ(stack(0).State(), NmtState::kPreOperational);
  EXPECT_EQ(stack(1).State(), NmtState::kOperational);
}

// §3.2.7: "The 'save' action on either CAN buses will apply to the parameters on both buses":
// "save all" on CAN2 keeps the shared application objects and both ports' communication objects
// through a power-on.
TEST_F(DataLoggerStorageTest, StoreOnPortTwoThenPowerOn) {
  Write(1, kTcHighWarning, 1, 6000, 2);  // shared, written on CAN2
  Write(0, 0x1017, 0, 200, 2);           // CAN1's own heartbeat
  Write(1, 0x1800, 5, 250, 2);           // CAN2's own TPDO1 timer
  Write(1, 0x1010, 1, canopen::kSaveSignature, 4);
  Write(1, kTcHighWarning, 2, 6000, 2);  // after the save: lost at power-off
  Boot();
  EXPECT_EQ(Read(0, kTcHighWarning, 1, true), 6000);
  EXPECT_EQ(Read(1, kTcHighWarning, 1, true), 6000);
  EXPECT_EQ(Read(0, kTcHighWarning, 2, true), 0);
  EXPECT_EQ(Read(0, 0x1017, 0), 200);
  EXPECT_EQ(Read(1, 0x1017, 0), 0);
  EXPECT_EQ(Read(1, 0x1800, 5), 250);
  EXPECT_EQ(Read(0, 0x1800, 5), 100);
}

// §3.2.8: "load" on either bus restores both buses' defaults, at the next reset or power-on.
TEST_F(DataLoggerStorageTest, RestoreOnPortOneCoversBothPorts) {
  Write(0, kTcHighWarning, 1, 6000, 2);
  Write(1, 0x1800, 5, 250, 2);
  Write(0, 0x1010, 1, canopen::kSaveSignature, 4);
  Boot();
  ASSERT_EQ(Read(1, 0x1800, 5), 250);
  Write(0, 0x1011, 1, canopen::kLoadSignature, 4);
  EXPECT_EQ(Read(0, kTcHighWarning, 1, true), 6000);  // "will NOT start using the default values right away"
  Boot();
  EXPECT_EQ(Read(0, kTcHighWarning, 1, true), 0);
  EXPECT_EQ(Read(1, 0x1800, 5), 100);
}

// README "Faults on two ports": a device fault reaches both ports' EMCY producers and 1003h.
// A stopped port sends no EMCY (CiA 301 §7.3.2.2) but records the fault in its 1003h/1001h.
TEST_F(PortsTest, DeviceFaultOnBothPorts) {
  SilenceTpdos();
  Send(1, "000#0206");                 // CAN2 stopped
  SetNumber("VPS.voltage_mV", 40000);  // > 5023h = 35 V
  Advance(10ms);
  EXPECT_EQ(Frames(0, "085#"), std::vector<std::string>{Emcy(kNode1, 0x3000, 0x01, 0x00, 0x20)});
  EXPECT_TRUE(Frames(1).empty());
  EXPECT_EQ(ErrorField(0), std::vector<std::uint32_t>{0x20003000});
  Send(1, "000#8006");  // CAN2 pre-operational: its SDO server answers again
  EXPECT_EQ(ErrorField(1), std::vector<std::uint32_t>{0x20003000});
  EXPECT_EQ(Read(1, 0x1001, 0), 1);
}

// README "Faults on two ports": communication faults stay on their port. A heartbeat consumer on
// CAN2 (1016h) loses node 20h: only CAN2 reports 80208130h (Table 26).
TEST_F(PortsTest, CommunicationFaultStaysOnItsPort) {
  Write(1, 0x1016, 1, (0x20u << 16) | 100u, 4);
  Send(1, "720#05");
  Advance(150ms);
  EXPECT_EQ(Frames(1, "086#"), std::vector<std::string>{Emcy(kNode2, 0x8130, 0x01, 0x20, 0x80)});
  EXPECT_EQ(ErrorField(1), std::vector<std::uint32_t>{0x80208130});
  EXPECT_TRUE(Frames(0, "085#").empty());
  EXPECT_TRUE(ErrorField(0).empty());
}

// A bus-off of CAN1's controller leaves CAN2 transmitting; after recovery CAN1 reports 00008140h
// (Table 26, README C29), then the error reset that removes the entry from 1003h (§3.2.4:
// "immediately removed when the error condition has been cleared"), and resumes; CAN2 never saw
// the error.
TEST_F(PortsTest, BusOffOnOnePortLeavesTheOtherTransmitting) {
  StartBoth();
  Advance(100ms);
  Frames(0);
  Frames(1);
  port1_.SetControllerState({ControllerState::kBusOff, 256, 0});
  Advance(500ms);
  EXPECT_TRUE(Frames(0).empty());
  EXPECT_EQ(Frames(1, "186#").size(), 5u);
  EXPECT_EQ(stack(0).State(), NmtState::kOperational);  // 1029h sub 1 = 1: no state change
  port1_.SetControllerState({ControllerState::kErrorActive, 0, 0});
  Advance(100ms);
  std::vector<std::string> emcy, tpdo1;
  for (auto& f : Frames(0)) {
    if (f.starts_with("085#")) emcy.push_back(f);
    if (f.starts_with("185#")) tpdo1.push_back(f);
  }
  EXPECT_EQ(emcy, (std::vector<std::string>{Emcy(kNode1, 0x8140, 0x01, 0x00, 0x00), EmcyReset(kNode1, 0)}));
  EXPECT_EQ(tpdo1.size(), 1u);
  EXPECT_TRUE(ErrorField(0).empty());  // 1003h sub 0 = 0: error-free again
  EXPECT_TRUE(Frames(1, "086#").empty());
  EXPECT_TRUE(ErrorField(1).empty());
}

// README "Reset node": a reset node on CAN2 resets the device's application (the shared objects
// go back to their power-on values, here the factory TC limits of 0, which trip at room
// temperature again), while CAN1 keeps its NMT state and its own communication objects and sends
// no boot-up.
TEST_F(PortsTest, ResetNodeOnOnePortResetsTheApplicationOnly) {
  Write(0, 0x1017, 0, 0, 2);
  Write(0, 0x1800, 5, 0, 2);
  Start(0);
  Send(1, "000#8106");  // reset node, CAN2
  EXPECT_EQ(Frames(1, "706#"), std::vector<std::string>{"706#00"});
  EXPECT_EQ(stack(0).State(), NmtState::kOperational);
  EXPECT_EQ(Read(0, kTcHighWarning, 1, true), 0);
  EXPECT_EQ(Read(0, 0x1800, 5), 0);  // CAN1's communication objects are its own
  Advance(10ms);
  EXPECT_EQ(Frames(0, "085#").size(), 8u);  // both high limits of four TCs, again
  EXPECT_EQ(Frames(1, "086#").size(), 8u);
  EXPECT_TRUE(Frames(0, "705#").empty());
}

// The same from CAN1: its stack restores the shared objects itself; CAN2 stays as it was.
TEST_F(PortsTest, ResetNodeOnPortOne) {
  Start(1);
  Write(1, kTcHighWarning, 3, 6000, 2);
  Send(0, "000#8105");
  EXPECT_EQ(Frames(0, "705#"), std::vector<std::string>{"705#00"});
  EXPECT_EQ(stack(1).State(), NmtState::kOperational);
  EXPECT_EQ(Read(1, kTcHighWarning, 3, true), 0);
}

// Design decision 10: with steady inputs nothing wakes; a pin change costs one cycle.
TEST_F(PortsTest, NoWakeUpsWhileSteady) {
  const auto fired = scheduler_.FiredCount();
  const auto cycles = logger().Cycles();
  Advance(10s);
  EXPECT_EQ(scheduler_.FiredCount(), fired);
  EXPECT_EQ(logger().Cycles(), cycles);
  SetNumber("IN4.voltage_mV", 1000);
  Advance(10s);
  EXPECT_EQ(logger().Cycles(), cycles + 1);
  SetNumber("TC1.temperature_C", 30);
  Advance(10s);
  EXPECT_EQ(logger().Cycles(), cycles + 2);
  EXPECT_EQ(Read(1, kTcFieldValue, 1, true), 300);
}

}  // namespace
}  // namespace canfleet::devices::test
