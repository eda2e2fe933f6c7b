#include "bus/capture/socketcan_layout.hpp"

#include <algorithm>

namespace canfleet::capture {

SocketCanFrame ToSocketCan(const CanFrame& frame) {
  SocketCanFrame out;
  if (frame.error()) {
    out.len = kCanErrDlc;
    if (frame.dlc == kCanErrDlc) {
      out.can_id = kCanErrFlag | (frame.id & kCanErrMask);
      out.data = frame.data;
    } else {
      out.can_id = kCanErrFlag | kCanErrProt | kCanErrBusError;
    }
    return out;
  }
  out.can_id = frame.extended() ? kCanEffFlag | (frame.id & kCanEffMask) : frame.id & kCanSffMask;
  out.len = std::min<std::uint8_t>(frame.dlc, 8);
  if (frame.remote()) {
    out.can_id |= kCanRtrFlag;
  } else {
    std::copy_n(frame.data.begin(), out.len, out.data.begin());
  }
  return out;
}

}  // namespace canfleet::capture
