#pragma once
/// @file Pure translation between canfleet's CanFrame and Linux SocketCAN's `struct can_frame`,
/// and from SocketCAN error frames to controller fault-confinement states. No I/O: unit-testable
/// on any Linux host, with or without CAN support in its kernel.
///
/// `struct can_frame` (linux/can.h, classical CAN, CAN_MTU = 16 bytes):
///
///     byte 0..3  can_id   bit 31 CAN_EFF_FLAG  29-bit identifier
///                         bit 30 CAN_RTR_FLAG  remote transmission request
///                         bit 29 CAN_ERR_FLAG  error message frame (class bits in 0..28)
///                         bits 0..28           identifier (11 bits used unless EFF)
///     byte 4     len      0..8 (the DLC of a classical frame)
///     byte 5..7  padding, len8_dlc
///     byte 8..15 data
///
/// Error frames (linux/can/error.h) are mapped to CanFrame with the kError flag, the error class
/// bits (CAN_ERR_MASK part of can_id: CAN_ERR_CRTL, CAN_ERR_BUSOFF, ...) as `id` and the eight
/// detail bytes as `data` (data[1] controller status, data[6]/[7] TEC/REC when CAN_ERR_CNT).

#include <linux/can.h>

#include <optional>

#include "bus/bus_port.hpp"
#include "bus/can_frame.hpp"

namespace canfleet {

/// CanFrame → kernel frame. The identifier is masked to its format (11 or 29 bits), the DLC is
/// clamped to 8, bytes beyond the DLC (and all bytes of a remote frame) are zero.
/// An error frame (kError) becomes CAN_ERR_FLAG | (id & CAN_ERR_MASK) with len CAN_ERR_DLC.
can_frame ToKernelFrame(const CanFrame& frame);

/// Kernel frame → CanFrame. Returns nothing for a frame that is not a classical CAN frame
/// (len > 8): such a frame is dropped by the caller, never trusted.
std::optional<CanFrame> FromKernelFrame(const can_frame& frame);

/// The fault-confinement state an error frame announces, with the counters it carries:
///   - CAN_ERR_BUSOFF                                  → bus-off (TEC reported as 256: > 255 by
///     definition, ISO 11898-1 §12.1.4.2)
///   - CAN_ERR_CRTL with CAN_ERR_CRTL_{RX,TX}_PASSIVE  → error-passive
///   - CAN_ERR_RESTARTED, or CAN_ERR_CRTL with CAN_ERR_CRTL_ACTIVE or only {RX,TX}_WARNING
///                                                     → error-active (warning is error-active:
///     ISO 11898-1 knows no warning state; the kernel reports the highest of the TX/RX states, so
///     a frame naming only a warning level means neither side is passive)
/// TEC/REC come from data[6]/data[7] when CAN_ERR_CNT is set, otherwise they are the threshold
/// of the announced state (128 on the passive side(s), 0 when error-active).
/// Any other error frame (bus errors, lost arbitration, ACK errors, overflows, transceiver
/// status) announces no state: nothing is returned. A frame without kError returns nothing.
std::optional<ControllerEvent> ControllerEventFromErrorFrame(const CanFrame& error_frame);

/// Follows a controller's state through its error frames and reports changes only, as
/// BusPort::OnStateChange promises.
class ControllerStateTracker {
 public:
  /// Returns the event when the error frame moves the controller to another state.
  std::optional<ControllerEvent> OnErrorFrame(const CanFrame& error_frame);
  ControllerState State() const { return current_.state; }
  const ControllerEvent& Last() const { return current_; }

 private:
  ControllerEvent current_;
};

}  // namespace canfleet
