#include "bus/socketcan/socketcan_codec.hpp"

#include <linux/can/error.h>

#include <algorithm>
#include <cstring>

namespace canfleet {

can_frame ToKernelFrame(const CanFrame& frame) {
  can_frame out;
  std::memset(&out, 0, sizeof out);
  if (frame.error()) {
    out.can_id = CAN_ERR_FLAG | (frame.id & CAN_ERR_MASK);
    out.len = CAN_ERR_DLC;
    std::copy(frame.data.begin(), frame.data.end(), out.data);
    return out;
  }
  const auto dlc = std::min<std::uint8_t>(frame.dlc, CAN_MAX_DLEN);
  if (frame.extended()) {
    out.can_id = CAN_EFF_FLAG | (frame.id & CAN_EFF_MASK);
  } else {
    out.can_id = frame.id & CAN_SFF_MASK;
  }
  out.len = dlc;
  if (frame.remote()) {
    out.can_id |= CAN_RTR_FLAG;
  } else {
    std::copy_n(frame.data.begin(), dlc, out.data);
  }
  return out;
}

std::optional<CanFrame> FromKernelFrame(const can_frame& frame) {
  if (frame.len > CAN_MAX_DLEN) return std::nullopt;
  CanFrame out;
  out.dlc = frame.len;
  if ((frame.can_id & CAN_ERR_FLAG) != 0) {
    out.flags = CanFrame::kError;
    out.id = frame.can_id & CAN_ERR_MASK;
    std::copy_n(frame.data, frame.len, out.data.begin());
    return out;
  }
  if ((frame.can_id & CAN_EFF_FLAG) != 0) {
    out.flags |= CanFrame::kExtended;
    out.id = frame.can_id & CAN_EFF_MASK;
  } else {
    out.id = frame.can_id & CAN_SFF_MASK;
  }
  if ((frame.can_id & CAN_RTR_FLAG) != 0) {
    out.flags |= CanFrame::kRemote;
  } else {
    std::copy_n(frame.data, frame.len, out.data.begin());
  }
  return out;
}

std::optional<ControllerEvent> ControllerEventFromErrorFrame(const CanFrame& error_frame) {
  if (!error_frame.error()) return std::nullopt;
  const std::uint32_t error_class = error_frame.id;
  const std::uint8_t controller = (error_class & CAN_ERR_CRTL) != 0 ? error_frame.data[1] : 0;
  const bool tx_passive = (controller & CAN_ERR_CRTL_TX_PASSIVE) != 0;
  const bool rx_passive = (controller & CAN_ERR_CRTL_RX_PASSIVE) != 0;
  const bool counted = (error_class & CAN_ERR_CNT) != 0;

  ControllerEvent event;
  if ((error_class & CAN_ERR_BUSOFF) != 0) {
    event.state = ControllerState::kBusOff;
    event.tec = 256;
    event.rec = counted ? error_frame.data[7] : 0;
    return event;
  }
  if (tx_passive || rx_passive) {
    event.state = ControllerState::kErrorPassive;
    event.tec = counted ? error_frame.data[6] : (tx_passive ? 128 : 0);
    event.rec = counted ? error_frame.data[7] : (rx_passive ? 128 : 0);
    return event;
  }
  const bool active =
      (error_class & CAN_ERR_RESTARTED) != 0 ||
      (controller & (CAN_ERR_CRTL_ACTIVE | CAN_ERR_CRTL_TX_WARNING | CAN_ERR_CRTL_RX_WARNING)) != 0;
  if (!active) return std::nullopt;
  event.state = ControllerState::kErrorActive;
  event.tec = counted ? error_frame.data[6] : 0;
  event.rec = counted ? error_frame.data[7] : 0;
  return event;
}

std::optional<ControllerEvent> ControllerStateTracker::OnErrorFrame(const CanFrame& error_frame) {
  auto event = ControllerEventFromErrorFrame(error_frame);
  if (!event) return std::nullopt;
  const bool changed = event->state != current_.state;
  current_ = *event;
  if (!changed) return std::nullopt;
  return event;
}

}  // namespace canfleet
