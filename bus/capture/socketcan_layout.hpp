#pragma once
/// @file How a CanFrame looks as a Linux SocketCAN `struct can_frame`, the one frame layout both
/// capture formats share (candump prints it, pcap LINKTYPE_CAN_SOCKETCAN stores it). Kept free of
/// <linux/can.h> so captures build anywhere; the constants are those of linux/can.h and
/// linux/can/error.h.
///
///     can_id  bit 31 CAN_EFF_FLAG  29-bit identifier
///             bit 30 CAN_RTR_FLAG  remote transmission request
///             bit 29 CAN_ERR_FLAG  error message frame (class bits in 0..28)
///             bits 0..28           identifier (11 bits used unless EFF)
///     len     0..8 (CAN_ERR_DLC = 8 for error frames)
///     data    8 bytes, zero beyond len (all zero for a remote frame)

#include <array>
#include <cstdint>

#include "bus/can_frame.hpp"

namespace canfleet::capture {

inline constexpr std::uint32_t kCanEffFlag = 0x80000000U;
inline constexpr std::uint32_t kCanRtrFlag = 0x40000000U;
inline constexpr std::uint32_t kCanErrFlag = 0x20000000U;
inline constexpr std::uint32_t kCanSffMask = 0x000007FFU;
inline constexpr std::uint32_t kCanEffMask = 0x1FFFFFFFU;
inline constexpr std::uint32_t kCanErrMask = 0x1FFFFFFFU;
inline constexpr std::uint8_t kCanErrDlc = 8;
/// Error classes (linux/can/error.h) used for a broker's failed transfer.
inline constexpr std::uint32_t kCanErrProt = 0x00000008U;      ///< protocol violation
inline constexpr std::uint32_t kCanErrBusError = 0x00000080U;  ///< bus error

/// A frame in SocketCAN terms.
struct SocketCanFrame {
  std::uint32_t can_id = 0;  ///< identifier with the EFF/RTR/ERR flag bits
  std::uint8_t len = 0;
  std::array<std::uint8_t, 8> data{};
};

/// CanFrame → SocketCAN. Data and remote frames map as bus/socketcan's ToKernelFrame does
/// (identifier masked to its format, DLC clamped to 8, bytes beyond it zero).
///
/// Error frames come in two forms and both become a SocketCAN error frame (CAN_ERR_FLAG, len 8):
///   - with DLC 8, the form bus/socketcan reads from a kernel: `id` holds the error class bits and
///     `data` the detail bytes; they are kept as they are;
///   - with DLC 0, the broker's form (a failed transfer; `id` names the frame that failed): written
///     as CAN_ERR_PROT | CAN_ERR_BUSERROR with unspecified type and location, which is how a
///     SocketCAN controller reports a corrupted transfer it took part in. The failed identifier
///     has no place in a SocketCAN error frame and is not kept.
SocketCanFrame ToSocketCan(const CanFrame& frame);

}  // namespace canfleet::capture
