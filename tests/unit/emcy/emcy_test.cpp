// The EMCY producer: frame layout (CiA 301 v4.2 §7.2.7.3.1), error register 1001h (§7.5.2.2),
// error reset (§7.2.7.1), NMT gating (§7.3.2.2 table 51) and the node-ID-relative COB-ID.
#include "tests/unit/emcy/emcy_fixture.hpp"

namespace canfleet::canopen {
namespace {

// §7.2.7.3.1: code LE in bytes 0-1, 1001h in byte 2, manufacturer bytes 3-7; COB-ID 80h + node-ID.
TEST_F(EmcyTest, RaiseSendsCodeRegisterAndManufacturerBytes) {
  auto& emcy = Start();
  // Quad controller: short circuit on POUT3 → 1003h 0x04032320.
  emcy.Raise(Error(0x2320, 0x0403, kErrorRegisterCurrent, {0x04, 0x03, 0xAA, 0xBB, 0xCC}));
  EXPECT_EQ(probe.Take(), std::vector<std::string>{"085#2023030403AABBCC"});
  EXPECT_EQ(Get(0x1001), 0x03u);
  EXPECT_EQ(ErrorField(), std::vector<std::uint32_t>{0x04032320});
  EXPECT_TRUE(emcy.IsActive(0x2320, 0x0403));
  EXPECT_EQ(emcy.ActiveCount(), 1u);
  EXPECT_EQ(emcy.ErrorRegister(), 0x03);
}

// §7.5.2.2: 1001h bit 0 (generic) is set while any error is active, with the bits of every active
// error OR-ed; bit 6 is reserved and stays 0.
TEST_F(EmcyTest, ErrorRegisterOrsTheBitsOfAllActiveErrors) {
  auto& emcy = Start();
  emcy.Raise(Error(0x3300, 0x0101, 0x00));
  emcy.Raise(Error(0x4210, 0x0000, kErrorRegisterTemperature));
  emcy.Raise(Error(0x8130, 0x0801, 0x10 | 0x40));
  EXPECT_EQ(probe.Take(), (std::vector<std::string>{"085#0033010000000000", "085#1042090000000000",
                                                    "085#3081190000000000"}));
  EXPECT_EQ(Get(0x1001), 0x19u);
  emcy.Clear(0x4210, 0x0000);
  EXPECT_EQ(Get(0x1001), 0x11u);
}

// Raising an error that is already active is not a new event: no frame, no second 1003h entry.
// The same code with another manufacturer part is another error.
TEST_F(EmcyTest, RaisingAnActiveErrorAgainChangesNothing) {
  auto& emcy = Start();
  emcy.Raise(Error(0x8130, 0x0802, 0x10));
  probe.Clear();
  emcy.Raise(Error(0x8130, 0x0802, 0x10));
  EXPECT_EQ(probe.Count(), 0u);
  EXPECT_EQ(ErrorField(), std::vector<std::uint32_t>{0x08028130});
  emcy.Raise(Error(0x8130, 0x0803, 0x10));
  EXPECT_EQ(probe.Take(), std::vector<std::string>{"085#3081110000000000"});
  EXPECT_EQ(ErrorField(), (std::vector<std::uint32_t>{0x08038130, 0x08028130}));
  EXPECT_EQ(emcy.ActiveCount(), 2u);
}

// Table 21: 0000h is "error reset or no error"; it cannot be raised as an error.
TEST_F(EmcyTest, CodeZeroCannotBeRaised) {
  auto& emcy = Start();
  emcy.Raise(Error(0x0000, 0x1234));
  EXPECT_EQ(probe.Count(), 0u);
  EXPECT_EQ(emcy.ActiveCount(), 0u);
  EXPECT_EQ(Get(0x1001), 0u);
}

// §7.2.7.1 error state diagram, transition 5: when the last error goes, EMCY 0000h with the
// (now zero) error register and zero manufacturer bytes; the device manuals remove the entry.
TEST_F(EmcyTest, ClearingTheLastErrorSendsErrorResetAndRemovesTheEntry) {
  auto& emcy = Start();
  emcy.Raise(Error(0x2320, 0x0403, kErrorRegisterCurrent, {1, 2, 3, 4, 5}));
  probe.Clear();
  emcy.Clear(0x2320, 0x0403);
  EXPECT_EQ(probe.Take(), std::vector<std::string>{"085#0000000000000000"});
  EXPECT_EQ(Get(0x1001), 0u);
  EXPECT_TRUE(ErrorField().empty());
  EXPECT_FALSE(emcy.IsActive(0x2320, 0x0403));
}

// Transition 3: one of several errors goes; the error reset carries the remaining register
// (CANopenNode sends one per cleared error). Only that error's entry leaves 1003h, order kept.
TEST_F(EmcyTest, PartialClearSendsErrorResetWithTheRemainingRegister) {
  auto& emcy = Start();
  emcy.Raise(Error(0x2320, 0x0401, kErrorRegisterCurrent));
  emcy.Raise(Error(0x3300, 0x0102, kErrorRegisterVoltage));
  emcy.Raise(Error(0x2320, 0x0403, kErrorRegisterCurrent));
  probe.Clear();
  emcy.Clear(0x3300, 0x0102);
  EXPECT_EQ(probe.Take(), std::vector<std::string>{"085#0000030000000000"});
  EXPECT_EQ(ErrorField(), (std::vector<std::uint32_t>{0x04032320, 0x04012320}));
  emcy.Clear(0x2320, 0x0403);
  EXPECT_EQ(probe.Take(), std::vector<std::string>{"085#0000030000000000"});
  EXPECT_EQ(ErrorField(), std::vector<std::uint32_t>{0x04012320});
  emcy.Clear(0x2320, 0x0401);
  EXPECT_EQ(probe.Take(), std::vector<std::string>{"085#0000000000000000"});
  EXPECT_TRUE(ErrorField().empty());
}

// Transition 3 says "may": with the option off only the last clear sends the error reset.
TEST_F(EmcyTest, PartialClearIsSilentWhenConfigured) {
  auto& emcy = Start({.reset_emcy_on_partial_clear = false});
  emcy.Raise(Error(0x2320, 0x0401));
  emcy.Raise(Error(0x2320, 0x0402));
  probe.Clear();
  emcy.Clear(0x2320, 0x0401);
  EXPECT_EQ(probe.Count(), 0u);
  EXPECT_EQ(Get(0x1001), 0x01u);
  emcy.Clear(0x2320, 0x0402);
  EXPECT_EQ(probe.Take(), std::vector<std::string>{"085#0000000000000000"});
}

// Clearing what is not active is not an event.
TEST_F(EmcyTest, ClearingAnInactiveErrorDoesNothing) {
  auto& emcy = Start();
  emcy.Raise(Error(0x2320, 0x0401));
  probe.Clear();
  emcy.Clear(0x2320, 0x0499);
  emcy.Clear(0x3300, 0x0401);
  EXPECT_EQ(probe.Count(), 0u);
  EXPECT_EQ(emcy.ActiveCount(), 1u);
  EXPECT_EQ(ErrorField(), std::vector<std::uint32_t>{0x04012320});
}

// §7.3.2.2 table 51: no EMCY in Stopped; the error is still recorded (1001h, 1003h), and it is
// not sent later when the node returns to Pre-operational. Operational sends.
TEST_F(EmcyTest, StoppedRecordsErrorsWithoutSendingThem) {
  auto& emcy = Start();
  emcy.SetNmtState(NmtState::kStopped);
  emcy.Raise(Error(0x2320, 0x0401, kErrorRegisterCurrent));
  EXPECT_EQ(probe.Count(), 0u);
  EXPECT_EQ(Get(0x1001), 0x03u);
  EXPECT_EQ(ErrorField(), std::vector<std::uint32_t>{0x04012320});
  emcy.SetNmtState(NmtState::kPreOperational);
  scheduler.Advance(1s);
  EXPECT_EQ(probe.Count(), 0u);
  emcy.SetNmtState(NmtState::kOperational);
  emcy.Clear(0x2320, 0x0401);
  EXPECT_EQ(probe.Take(), std::vector<std::string>{"085#0000000000000000"});
}

// The producer starts in Initialising: nothing goes out before the stack reports an NMT state.
TEST_F(EmcyTest, NothingIsSentBeforeTheNmtStateIsKnown) {
  AddEmcyObjects(od, 4);
  od.RestoreDefaults(0x1000, 0x1FFF, 5);
  Emcy emcy(od, node, scheduler);
  emcy.SetNodeId(5);
  emcy.Raise(Error(0x5000));
  EXPECT_EQ(probe.Count(), 0u);
  EXPECT_EQ(Get(0x1001), 0x01u);
}

// CiA 301 predefined connection set: EMCY = 80h + node-ID; 1014h (§7.5.2.17) reads it.
TEST_F(EmcyTest, DefaultCobIdFollowsTheNodeId) {
  auto& emcy = Start();
  EXPECT_EQ(Get(0x1014), 0x85u);
  emcy.SetNodeId(0x20);
  EXPECT_EQ(Get(0x1014), 0xA0u);
  emcy.Raise(Error(0x5000));
  EXPECT_EQ(probe.Take(), std::vector<std::string>{"0A0#0050010000000000"});
}

// An unconfigured node (LSS node-ID FFh) has no default COB-ID: errors are recorded, not sent.
TEST_F(EmcyTest, NodeIdOutsideOneTo127SendsNothing) {
  auto& emcy = Start();
  emcy.SetNodeId(0xFF);
  emcy.Raise(Error(0x5000));
  EXPECT_EQ(probe.Count(), 0u);
  EXPECT_EQ(emcy.ActiveCount(), 1u);
}

// LastSent and OnSent report what the port accepted; a refused frame (bus-off) is not reported
// but the error is still recorded.
TEST_F(EmcyTest, LastSentAndOnSentReportAcceptedFrames) {
  auto& emcy = Start();
  std::vector<std::string> seen;
  emcy.OnSent([&](const CanFrame& f) { seen.push_back(ToCandump(f)); });
  EXPECT_FALSE(emcy.LastSent().has_value());
  emcy.Raise(Error(0x2320, 0x0403, kErrorRegisterCurrent, {4, 3, 0, 0, 0}));
  ASSERT_TRUE(emcy.LastSent().has_value());
  EXPECT_EQ(*emcy.LastSent(), test::Frame("085#2023030403000000"));
  node.SetControllerState({ControllerState::kBusOff, 256, 0});
  emcy.Raise(Error(0x8140, 0x0000, 0x10));
  EXPECT_EQ(seen, std::vector<std::string>{"085#2023030403000000"});
  EXPECT_EQ(*emcy.LastSent(), test::Frame("085#2023030403000000"));
  EXPECT_TRUE(emcy.IsActive(0x8140, 0));
  EXPECT_EQ(probe.Count(), 1u);
}

// CiA 301 8140h means "recovered from bus-off": the EMCY raised while the controller is bus-off
// cannot leave then, so it waits and is the first frame after recovery, followed by the error
// reset sent when the error clears (CANopenNode's EMCY FIFO behaves the same). The reset takes the
// entry out of 1003h like any other cleared error (CiA 301 §7.5.2.4; the manuals' 1003h sections).
TEST_F(EmcyTest, EmcyRefusedDuringBusOffLeavesAfterRecoveryInOrder) {
  auto& emcy = Start();
  node.SetControllerState({ControllerState::kBusOff, 256, 0});
  emcy.Raise(Error(0x8140, 0x0000, 0x10));
  emcy.Raise(Error(0x2320, 0x0403, kErrorRegisterCurrent, {4, 3, 0, 0, 0}));
  scheduler.Advance(std::chrono::seconds(1));
  EXPECT_EQ(probe.Count(), 0u);
  node.SetControllerState({ControllerState::kErrorActive, 0, 0});
  emcy.OnBusOffEnded();
  emcy.Clear(0x8140, 0x0000);
  scheduler.Advance(std::chrono::milliseconds(1));
  EXPECT_EQ(probe.Take(), (std::vector<std::string>{"085#4081110000000000", "085#2023130403000000",
                                                    "085#0000030000000000"}));
  EXPECT_FALSE(emcy.IsActive(0x8140, 0));
  EXPECT_EQ(std::vector<std::uint32_t>(emcy.History().begin(), emcy.History().end()),
            std::vector<std::uint32_t>{0x04032320u});
}

// Reset node: everything is forgotten without a frame (the node boots again).
TEST_F(EmcyTest, ClearAllForgetsErrorsAndHistorySilently) {
  auto& emcy = Start();
  emcy.Raise(Error(0x2320, 0x0401, kErrorRegisterCurrent));
  emcy.Raise(Error(0x3300, 0x0102, kErrorRegisterVoltage));
  probe.Clear();
  emcy.ClearAll();
  EXPECT_EQ(probe.Count(), 0u);
  EXPECT_EQ(emcy.ActiveCount(), 0u);
  EXPECT_EQ(Get(0x1001), 0u);
  EXPECT_EQ(Get(0x1003, 0), 0u);
  EXPECT_EQ(Get(0x1003, 1), 0u);
  emcy.Raise(Error(0x2320, 0x0401, kErrorRegisterCurrent));
  EXPECT_EQ(probe.Take(), std::vector<std::string>{"085#2023030000000000"});
}

// Devices without 1003h, 1014h and 1015h (the valve lists neither 1014h nor 1015h): EMCY on
// 80h + node-ID, no history, no inhibit time; without 1001h the register still goes in byte 2.
TEST_F(EmcyTest, MissingOptionalObjectsAreTolerated) {
  auto& emcy = StartOn();
  emcy.Raise(Error(0x2320, 0x0401, kErrorRegisterCurrent));
  emcy.Raise(Error(0x3300, 0x0402, kErrorRegisterVoltage));
  EXPECT_EQ(probe.Take(), (std::vector<std::string>{"085#2023030000000000", "085#0033070000000000"}));
  EXPECT_TRUE(emcy.History().empty());
  EXPECT_EQ(emcy.ErrorRegister(), 0x07);
}

TEST_F(EmcyTest, OnlyTheErrorFieldIsEnough) {
  AddEmcyObjects(od, 4);
  od.objects().erase(0x1014);
  od.objects().erase(0x1015);
  auto& emcy = StartOn();
  emcy.Raise(Error(0xF001, 0x2003));
  emcy.Raise(Error(0xF002, 0x1003));
  EXPECT_EQ(probe.Take(), (std::vector<std::string>{"085#01F0010000000000", "085#02F0010000000000"}));
  EXPECT_EQ(ErrorField(), (std::vector<std::uint32_t>{0x1003F002, 0x2003F001}));
}

}  // namespace
}  // namespace canfleet::canopen
