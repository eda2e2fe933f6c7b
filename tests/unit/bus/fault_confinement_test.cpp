// CAN controller fault confinement, ISO 11898-1 §12.1.4.
#include "bus/physics/fault_confinement.hpp"

#include <gtest/gtest.h>

namespace canfleet {
namespace {

TEST(FaultConfinement, SixteenTransmitErrorsMakeErrorPassiveThirtyTwoBusOff) {
  FaultConfinement c;
  for (int i = 0; i < 15; ++i)
    EXPECT_FALSE(c.OnTransmitError(TransmitError::kBit));
  EXPECT_EQ(c.Tec(), 120);
  auto passive = c.OnTransmitError(TransmitError::kBit);
  ASSERT_TRUE(passive);
  EXPECT_EQ(passive->state, ControllerState::kErrorPassive);
  EXPECT_EQ(passive->tec, 128);
  for (int i = 0; i < 15; ++i)
    EXPECT_FALSE(c.OnTransmitError(TransmitError::kBit));
  EXPECT_EQ(c.Tec(), 248);
  auto bus_off = c.OnTransmitError(TransmitError::kBit);  // 256 > 255
  ASSERT_TRUE(bus_off);
  EXPECT_EQ(bus_off->state, ControllerState::kBusOff);
}

TEST(FaultConfinement, BusOffWhenTecExceeds255) {
  FaultConfinement c;
  std::optional<ControllerEvent> last;
  int errors = 0;
  while (c.State() != ControllerState::kBusOff && errors < 100) {
    if (auto e = c.OnTransmitError(TransmitError::kBit)) last = e;
    ++errors;
  }
  ASSERT_TRUE(last);
  EXPECT_EQ(last->state, ControllerState::kBusOff);
  EXPECT_EQ(c.Tec(), 256);
  EXPECT_EQ(errors, 32);
  // Nothing counts while bus-off; only recovery leaves it.
  EXPECT_FALSE(c.OnTransmitSuccess());
  EXPECT_FALSE(c.OnReceiveError());
  auto recovered = c.Recover();
  ASSERT_TRUE(recovered);
  EXPECT_EQ(recovered->state, ControllerState::kErrorActive);
  EXPECT_EQ(c.Tec(), 0);
  EXPECT_EQ(c.Rec(), 0);
}

TEST(FaultConfinement, NodeAloneOnTheBusStopsAtErrorPassive) {
  FaultConfinement c;
  for (int i = 0; i < 1000; ++i)
    c.OnTransmitError(TransmitError::kAck);
  EXPECT_EQ(c.State(), ControllerState::kErrorPassive);
  EXPECT_EQ(c.Tec(), 128);
}

TEST(FaultConfinement, SuccessfulTransmissionsBringTheNodeBackToErrorActive) {
  FaultConfinement c;
  for (int i = 0; i < 16; ++i)
    c.OnTransmitError(TransmitError::kBit);
  ASSERT_EQ(c.State(), ControllerState::kErrorPassive);
  std::optional<ControllerEvent> back;
  for (int i = 0; i < 1 && !back; ++i)
    back = c.OnTransmitSuccess();
  ASSERT_TRUE(back);  // 127 < 128
  EXPECT_EQ(back->state, ControllerState::kErrorActive);
}

TEST(FaultConfinement, ReceiveErrorsMakeErrorPassiveAndASuccessBringsRecBelow128) {
  FaultConfinement c;
  for (int i = 0; i < 127; ++i)
    EXPECT_FALSE(c.OnReceiveError());
  auto passive = c.OnReceiveError();
  ASSERT_TRUE(passive);
  EXPECT_EQ(passive->rec, 128);
  for (int i = 0; i < 200; ++i)
    c.OnReceiveError();
  EXPECT_EQ(c.Rec(), 255);  // saturates: REC never makes a node bus-off
  auto active = c.OnReceiveSuccess();
  ASSERT_TRUE(active);
  EXPECT_EQ(active->state, ControllerState::kErrorActive);
  EXPECT_LE(c.Rec(), 127);
  EXPECT_GE(c.Rec(), 119);
}

TEST(FaultConfinement, ForcedBusOffForFaultInjection) {
  FaultConfinement c;
  auto e = c.ForceBusOff();
  ASSERT_TRUE(e);
  EXPECT_EQ(e->state, ControllerState::kBusOff);
  EXPECT_FALSE(c.ForceBusOff());
  EXPECT_TRUE(c.Recover());
}

// Fault injection: an error-passive hold. TEC jumps to 128 (event), successes stop at 128, errors
// still count (rule 3) up to bus-off; a recovery while held ends error-passive at 128.
TEST(FaultConfinement, AHeldControllerStaysErrorPassive) {
  FaultConfinement c;
  c.OnTransmitError(TransmitError::kBit);  // TEC 8
  auto held = c.HoldErrorPassive(true);
  ASSERT_TRUE(held);
  EXPECT_EQ(held->state, ControllerState::kErrorPassive);
  EXPECT_EQ(held->tec, 128);
  EXPECT_FALSE(c.HoldErrorPassive(true));
  for (int i = 0; i < 300; ++i)
    EXPECT_FALSE(c.OnTransmitSuccess());
  EXPECT_EQ(c.Tec(), 128);
  EXPECT_EQ(c.State(), ControllerState::kErrorPassive);
  EXPECT_FALSE(c.OnTransmitError(TransmitError::kAck));  // rule 3 exception 1 still holds
  for (int i = 0; i < 15; ++i)
    EXPECT_FALSE(c.OnTransmitError(TransmitError::kBit));
  auto bus_off = c.OnTransmitError(TransmitError::kBit);  // 128 + 16 × 8 = 256 > 255
  ASSERT_TRUE(bus_off);
  EXPECT_EQ(bus_off->state, ControllerState::kBusOff);
  auto recovered = c.Recover();
  ASSERT_TRUE(recovered);
  EXPECT_EQ(recovered->state, ControllerState::kErrorPassive);
  EXPECT_EQ(recovered->tec, 128);
  EXPECT_EQ(recovered->rec, 0);
}

// Released, TEC is min(TEC, 127): error-active again, counting down from there; REC is untouched,
// so REC ≥ 128 keeps the controller passive.
TEST(FaultConfinement, ReleasingTheHoldLeavesTec127) {
  FaultConfinement c;
  c.HoldErrorPassive(true);
  for (int i = 0; i < 5; ++i)
    c.OnTransmitError(TransmitError::kBit);  // TEC 168
  auto released = c.HoldErrorPassive(false);
  ASSERT_TRUE(released);
  EXPECT_EQ(released->state, ControllerState::kErrorActive);
  EXPECT_EQ(released->tec, 127);
  EXPECT_FALSE(c.HoldErrorPassive(false));
  c.OnTransmitSuccess();
  EXPECT_EQ(c.Tec(), 126);

  FaultConfinement r;
  for (int i = 0; i < 130; ++i)
    r.OnReceiveError();
  EXPECT_FALSE(r.HoldErrorPassive(true));  // already passive (REC): no event
  EXPECT_EQ(r.Tec(), 128);
  EXPECT_FALSE(r.HoldErrorPassive(false));  // still passive through REC 130
  EXPECT_EQ(r.Tec(), 127);
  EXPECT_EQ(r.State(), ControllerState::kErrorPassive);
}

// A hold set while bus-off takes effect at the recovery; released while bus-off, the recovery is
// the ordinary one.
TEST(FaultConfinement, AHoldSetWhileBusOffAppliesAtRecovery) {
  FaultConfinement c;
  c.ForceBusOff();
  EXPECT_FALSE(c.HoldErrorPassive(true));
  EXPECT_EQ(c.State(), ControllerState::kBusOff);
  EXPECT_EQ(c.Recover()->state, ControllerState::kErrorPassive);
  c.ForceBusOff();
  EXPECT_FALSE(c.HoldErrorPassive(false));
  auto recovered = c.Recover();
  EXPECT_EQ(recovered->state, ControllerState::kErrorActive);
  EXPECT_EQ(recovered->tec, 0);
}

// The broker's hot-loop test: nothing to count for an error-active receiver with REC 0.
TEST(FaultConfinement, ReceiveSuccessChangesNothingOnlyAtRest) {
  FaultConfinement c;
  EXPECT_TRUE(c.ReceiveSuccessChangesNothing());
  c.OnReceiveError();
  EXPECT_FALSE(c.ReceiveSuccessChangesNothing());
  c.OnReceiveSuccess();
  EXPECT_TRUE(c.ReceiveSuccessChangesNothing());
  c.ForceBusOff();
  EXPECT_FALSE(c.ReceiveSuccessChangesNothing());
}

}  // namespace
}  // namespace canfleet
