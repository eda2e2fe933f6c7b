// The pure SocketCAN translations: CanFrame <-> struct can_frame (linux/can.h) and error frames
// (linux/can/error.h) -> ISO 11898-1 fault-confinement states. No kernel CAN support needed.
#include "bus/socketcan/socketcan_codec.hpp"

#include <gtest/gtest.h>
#include <linux/can/error.h>

#include <cstring>

namespace canfleet {
namespace {

can_frame Kernel(canid_t id, std::initializer_list<std::uint8_t> bytes) {
  can_frame f;
  std::memset(&f, 0, sizeof f);
  f.can_id = id;
  f.len = static_cast<std::uint8_t>(bytes.size());
  std::copy(bytes.begin(), bytes.end(), f.data);
  return f;
}

CanFrame ErrorFrame(std::uint32_t error_class, std::array<std::uint8_t, 8> data = {}) {
  CanFrame f;
  f.flags = CanFrame::kError;
  f.id = error_class;
  f.dlc = CAN_ERR_DLC;
  f.data = data;
  return f;
}

TEST(SocketCanCodec, StandardDataFrameKeepsIdLengthAndBytes) {
  const can_frame k = ToKernelFrame(CanFrame::Data(0x123, {0xDE, 0xAD, 0xBE, 0xEF}));
  EXPECT_EQ(k.can_id, 0x123u);
  EXPECT_EQ(k.len, 4);
  EXPECT_EQ(std::vector<std::uint8_t>(k.data, k.data + 8),
            (std::vector<std::uint8_t>{0xDE, 0xAD, 0xBE, 0xEF, 0, 0, 0, 0}));
  EXPECT_EQ(FromKernelFrame(k), CanFrame::Data(0x123, {0xDE, 0xAD, 0xBE, 0xEF}));
}

TEST(SocketCanCodec, ExtendedIdentifierSetsEffFlag) {
  CanFrame f = CanFrame::Data(0x1ABCDEF0, {0x01});
  f.flags = CanFrame::kExtended;
  const can_frame k = ToKernelFrame(f);
  EXPECT_EQ(k.can_id, CAN_EFF_FLAG | 0x1ABCDEF0u);
  auto back = FromKernelFrame(k);
  ASSERT_TRUE(back);
  EXPECT_TRUE(back->extended());
  EXPECT_EQ(back->id, 0x1ABCDEF0u);
  EXPECT_EQ(ToCandump(*back), "1ABCDEF0#01");
}

TEST(SocketCanCodec, RemoteFrameKeepsDlcAndCarriesNoData) {
  CanFrame f = CanFrame::Remote(0x701, 2);
  f.data = {0xAA, 0xBB};  // must not leak onto the wire
  const can_frame k = ToKernelFrame(f);
  EXPECT_EQ(k.can_id, CAN_RTR_FLAG | 0x701u);
  EXPECT_EQ(k.len, 2);
  EXPECT_EQ(k.data[0], 0);
  auto back = FromKernelFrame(Kernel(CAN_RTR_FLAG | CAN_EFF_FLAG | 0x18FF0001, {}));
  ASSERT_TRUE(back);
  EXPECT_TRUE(back->remote());
  EXPECT_TRUE(back->extended());
  EXPECT_EQ(ToCandump(*back), "18FF0001#R");
}

TEST(SocketCanCodec, BytesBeyondTheDlcAreZeroOnTheWire) {
  CanFrame f = CanFrame::Data(0x181, {1, 2});
  f.data[5] = 0x55;  // stale byte beyond the DLC
  const can_frame k = ToKernelFrame(f);
  EXPECT_EQ(k.data[5], 0);
}

TEST(SocketCanCodec, StandardIdentifierIsMaskedToElevenBits) {
  // A raw socket may write junk above bit 10 of a standard id; candump shows can_id & CAN_SFF_MASK.
  auto back = FromKernelFrame(Kernel(0x1234, {7}));
  ASSERT_TRUE(back);
  EXPECT_EQ(back->id, 0x234u);
  EXPECT_FALSE(back->extended());
}

TEST(SocketCanCodec, LengthAboveEightIsRejected) {
  can_frame k = Kernel(0x100, {});
  k.len = 9;
  EXPECT_FALSE(FromKernelFrame(k));
  k.len = 64;
  EXPECT_FALSE(FromKernelFrame(k));
}

TEST(SocketCanCodec, ErrorFrameKeepsClassAndDetailBytes) {
  const can_frame k =
      Kernel(CAN_ERR_FLAG | CAN_ERR_CRTL | CAN_ERR_CNT, {0, CAN_ERR_CRTL_TX_PASSIVE, 0, 0, 0, 0, 130, 5});
  auto f = FromKernelFrame(k);
  ASSERT_TRUE(f);
  EXPECT_TRUE(f->error());
  EXPECT_FALSE(f->extended());
  EXPECT_EQ(f->id, static_cast<std::uint32_t>(CAN_ERR_CRTL | CAN_ERR_CNT));
  EXPECT_EQ(f->data[1], CAN_ERR_CRTL_TX_PASSIVE);
  const can_frame again = ToKernelFrame(*f);
  EXPECT_EQ(again.can_id, k.can_id);
  EXPECT_EQ(again.len, CAN_ERR_DLC);
  EXPECT_EQ(std::memcmp(again.data, k.data, 8), 0);
}

TEST(SocketCanCodec, EveryValidFrameSurvivesARoundTrip) {
  for (std::uint32_t id : {0x000u, 0x001u, 0x7FFu, 0x12345678u, 0x1FFFFFFFu}) {
    for (std::uint8_t dlc = 0; dlc <= 8; ++dlc) {
      for (std::uint8_t flags : {std::uint8_t{0}, std::uint8_t{CanFrame::kRemote}}) {
        CanFrame f;
        f.id = id;
        f.dlc = dlc;
        f.flags = flags;
        if (id > CanFrame::kMaxStandardId) f.flags |= CanFrame::kExtended;
        for (std::uint8_t i = 0; i < dlc; ++i)
          f.data[i] = static_cast<std::uint8_t>(0xA0 + i);
        if (f.remote()) f.data = {};
        auto back = FromKernelFrame(ToKernelFrame(f));
        ASSERT_TRUE(back);
        EXPECT_EQ(*back, f) << ToCandump(f);
      }
    }
  }
}

// --- error frames -> controller state (ISO 11898-1 §12.1.4.2 fault confinement) ---

TEST(SocketCanErrorState, TxPassiveMeansErrorPassiveWithTecAtThreshold) {
  auto e = ControllerEventFromErrorFrame(ErrorFrame(CAN_ERR_CRTL, {0, CAN_ERR_CRTL_TX_PASSIVE}));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->state, ControllerState::kErrorPassive);
  EXPECT_EQ(e->tec, 128);
  EXPECT_EQ(e->rec, 0);
}

TEST(SocketCanErrorState, RxPassiveMeansErrorPassiveWithRecAtThreshold) {
  auto e = ControllerEventFromErrorFrame(ErrorFrame(CAN_ERR_CRTL, {0, CAN_ERR_CRTL_RX_PASSIVE}));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->state, ControllerState::kErrorPassive);
  EXPECT_EQ(e->tec, 0);
  EXPECT_EQ(e->rec, 128);
}

TEST(SocketCanErrorState, CountersComeFromTheFrameWhenCanErrCntIsSet) {
  auto e = ControllerEventFromErrorFrame(
      ErrorFrame(CAN_ERR_CRTL | CAN_ERR_CNT, {0, CAN_ERR_CRTL_TX_PASSIVE, 0, 0, 0, 0, 136, 12}));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->tec, 136);
  EXPECT_EQ(e->rec, 12);
}

TEST(SocketCanErrorState, BusOffWinsAndReportsTecAbove255) {
  auto e =
      ControllerEventFromErrorFrame(ErrorFrame(CAN_ERR_BUSOFF | CAN_ERR_CRTL, {0, CAN_ERR_CRTL_TX_PASSIVE}));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->state, ControllerState::kBusOff);
  EXPECT_GT(e->tec, 255);
}

TEST(SocketCanErrorState, RestartedAndActiveAndWarningMeanErrorActive) {
  for (const CanFrame& f : {ErrorFrame(CAN_ERR_RESTARTED), ErrorFrame(CAN_ERR_CRTL, {0, CAN_ERR_CRTL_ACTIVE}),
                            ErrorFrame(CAN_ERR_CRTL, {0, CAN_ERR_CRTL_TX_WARNING}),
                            ErrorFrame(CAN_ERR_CRTL, {0, CAN_ERR_CRTL_RX_WARNING})}) {
    auto e = ControllerEventFromErrorFrame(f);
    ASSERT_TRUE(e) << ToCandump(f);
    EXPECT_EQ(e->state, ControllerState::kErrorActive);
  }
}

TEST(SocketCanErrorState, BusErrorsAndOverflowsAnnounceNoState) {
  for (const CanFrame& f :
       {ErrorFrame(CAN_ERR_PROT, {0, 0, CAN_ERR_PROT_BIT}), ErrorFrame(CAN_ERR_ACK),
        ErrorFrame(CAN_ERR_LOSTARB), ErrorFrame(CAN_ERR_BUSERROR), ErrorFrame(CAN_ERR_TX_TIMEOUT),
        ErrorFrame(CAN_ERR_CRTL, {0, CAN_ERR_CRTL_RX_OVERFLOW}), ErrorFrame(CAN_ERR_CRTL, {0, 0}),
        // passive bits without the CRTL class are not controller status
        ErrorFrame(CAN_ERR_PROT, {0, CAN_ERR_CRTL_TX_PASSIVE})}) {
    EXPECT_FALSE(ControllerEventFromErrorFrame(f)) << std::hex << f.id;
  }
}

TEST(SocketCanErrorState, DataFramesAreNotErrorFrames) {
  EXPECT_FALSE(ControllerEventFromErrorFrame(CanFrame::Data(0x004, {0, CAN_ERR_CRTL_TX_PASSIVE})));
}

TEST(SocketCanErrorState, TrackerReportsChangesOnly) {
  ControllerStateTracker tracker;
  EXPECT_EQ(tracker.State(), ControllerState::kErrorActive);
  EXPECT_FALSE(tracker.OnErrorFrame(ErrorFrame(CAN_ERR_CRTL, {0, CAN_ERR_CRTL_TX_WARNING})));  // still active
  auto passive = tracker.OnErrorFrame(ErrorFrame(CAN_ERR_CRTL, {0, CAN_ERR_CRTL_TX_PASSIVE}));
  ASSERT_TRUE(passive);
  EXPECT_EQ(passive->state, ControllerState::kErrorPassive);
  EXPECT_FALSE(tracker.OnErrorFrame(ErrorFrame(CAN_ERR_CRTL, {0, CAN_ERR_CRTL_RX_PASSIVE})));  // same state
  EXPECT_FALSE(tracker.OnErrorFrame(ErrorFrame(CAN_ERR_ACK)));
  auto bus_off = tracker.OnErrorFrame(ErrorFrame(CAN_ERR_BUSOFF));
  ASSERT_TRUE(bus_off);
  EXPECT_EQ(bus_off->state, ControllerState::kBusOff);
  EXPECT_EQ(tracker.State(), ControllerState::kBusOff);
  auto restarted = tracker.OnErrorFrame(ErrorFrame(CAN_ERR_RESTARTED));
  ASSERT_TRUE(restarted);
  EXPECT_EQ(restarted->state, ControllerState::kErrorActive);
  EXPECT_EQ(restarted->tec, 0);
}

}  // namespace
}  // namespace canfleet
