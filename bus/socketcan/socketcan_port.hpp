#pragma once
/// @file A BusPort on a SocketCAN interface (vcan0, can0...): a canfleet node runs on a real or
/// virtual Linux CAN bus exactly as on the broker.

#include <asio/io_context.hpp>
#include <memory>
#include <string>
#include <string_view>

#include "bus/bus_port.hpp"
#include "bus/socketcan/socketcan_codec.hpp"
#include "bus/socketcan/socketcan_socket.hpp"

namespace canfleet {

struct SocketCanPortOptions {
  SocketCanOptions socket;
  /// Also hand error frames (kError set, see socketcan_codec.hpp) to the receive handler. Off by
  /// default: the stack only needs the state changes, which always arrive through OnStateChange.
  bool deliver_error_frames = false;
};

/// A node's attachment to a SocketCAN interface over an AF_CAN raw socket.
///
/// - Received frames reach OnReceive in batches read with recvmmsg, with the kernel's receive time
///   (nanoseconds since the Unix epoch: a real bus has no other time line).
/// - Send queues the frame; the queue goes to the kernel with sendmmsg once per io_context turn.
/// - The controller state follows the error frames the kernel reports (error-passive, bus-off,
///   restarted: see ControllerEventFromErrorFrame); a change reaches OnStateChange. A vcan
///   interface has no controller and stays error-active unless someone writes error frames on it.
/// - The port never receives its own frames (CAN_RAW_RECV_OWN_MSGS off by default), as a node
///   never hears itself on a real bus; other sockets on the same interface do (CAN_RAW_LOOPBACK).
///
/// Handlers run on the thread running the io_context; a handler may destroy the port.
class SocketCanPort final : public BusPort {
 public:
  /// Opens and binds the interface. Throws SocketCanError when it cannot, e.g.
  /// "socketcan: vcan0: Address family not supported by protocol (the kernel has no CAN support)".
  SocketCanPort(asio::io_context& io, std::string_view interface, SocketCanPortOptions options = {});
  ~SocketCanPort() override;

  /// Queues a frame. False when the frame is invalid or an error frame (a controller does not send
  /// those), when the controller is bus-off or when the transmit queue is full.
  bool Send(const CanFrame& frame) override;
  ControllerState State() const override { return tracker_.State(); }

  /// Socket errors after opening (interface down or deleted, frames refused by the kernel).
  void OnError(SocketCanSocket::ErrorHandler handler) { on_error_ = std::move(handler); }

  const std::string& Interface() const { return socket_.Interface(); }
  const SocketCanStats& Stats() const { return socket_.Stats(); }

 private:
  void OnBatch(std::span<const CanFrame> frames, std::span<const BusTime> times);

  SocketCanPortOptions options_;
  ControllerStateTracker tracker_;
  SocketCanSocket::ErrorHandler on_error_;
  std::shared_ptr<int> alive_ = std::make_shared<int>(0);
  SocketCanSocket socket_;  // last: destroyed first, so no handler outlives the members above
};

}  // namespace canfleet
