#pragma once
/// @file Joins a canfleet virtual bus and a SocketCAN interface in both directions, so tools on
/// the Linux side (candump, cansend, python-can, Wireshark, a real PLC on can0) share a bus with
/// canfleet nodes.

#include <asio/io_context.hpp>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string_view>

#include "bus/bus_port.hpp"
#include "bus/socketcan/socketcan_codec.hpp"
#include "bus/socketcan/socketcan_socket.hpp"

namespace canfleet {

/// A two-way bridge between a virtual bus and a SocketCAN interface.
///
/// The virtual side is generic so that any transport can carry it: frames read from SocketCAN go
/// to a sink (`VirtualBusSink`, e.g. the broker's "a port transmitted these" entry point), and
/// frames of the virtual bus are given to FromVirtualBus(). ConnectTo() wires both to a BusPort
/// (a broker client port, or a LoopbackPort in tests).
///
/// No frame is echoed back to where it came from:
/// - SocketCAN → virtual bus: the bridge's socket never receives what the bridge itself wrote
///   (CAN_RAW_RECV_OWN_MSGS is forced off), so a frame from the virtual bus written to the
///   interface is not read back and forwarded again.
/// - virtual bus → SocketCAN: FromVirtualBus must be given the frames *other* ports sent, never the
///   ones the bridge put on the virtual bus through its sink. The broker and LoopbackBus already
///   deliver to every port but the sender; a transport with transmit confirmations must not pass
///   those in.
/// - CAN_RAW_LOOPBACK is forced on: other sockets on the interface (candump, canfleet nodes on a
///   SocketCanPort over vcan0) do see the frames bridged in from the virtual bus; that local echo
///   is how a virtual interface delivers at all, and a real controller's (IFF_ECHO) is what the
///   other local sockets expect.
/// - Error frames cross in neither direction: a SocketCAN error frame describes the bridge's own
///   controller (reported through OnSocketCanStateChange), and the virtual bus's error frames are
///   the broker's physics, which no CAN controller can transmit.
///
/// All calls and handlers on the thread that runs the io_context.
class SocketCanBridge {
 public:
  /// Receives frames read from SocketCAN, in order, in batches, to be sent on the virtual bus.
  using VirtualBusSink = std::function<void(std::span<const CanFrame>)>;

  struct Stats {
    std::uint64_t to_virtual_bus = 0;  ///< frames handed to the sink
    std::uint64_t to_socketcan = 0;    ///< frames from the virtual bus queued for the interface
    std::uint64_t dropped = 0;         ///< frames not forwarded: error frames, bus-off, full queue, no sink
  };

  /// Opens the interface (throws SocketCanError, see SocketCanSocket). `options.loopback` and
  /// `options.receive_own_messages` are overridden as explained above.
  SocketCanBridge(asio::io_context& io, std::string_view interface, VirtualBusSink to_virtual_bus = {},
                  SocketCanOptions options = {});
  ~SocketCanBridge();
  SocketCanBridge(const SocketCanBridge&) = delete;
  SocketCanBridge& operator=(const SocketCanBridge&) = delete;

  /// Replaces the sink (frames read while there is none are counted and dropped).
  void SetVirtualBusSink(VirtualBusSink sink) { to_virtual_bus_ = std::move(sink); }

  /// Frames other ports sent on the virtual bus: written to the interface in order. Returns how
  /// many were queued; error frames, frames while the controller is bus-off and frames beyond the
  /// transmit queue are dropped and counted.
  std::size_t FromVirtualBus(std::span<const CanFrame> frames);

  /// Wires the virtual side to a port: frames from SocketCAN are sent through `port.Send`, and the
  /// frames the port receives go to FromVirtualBus. Replaces the port's receive handler and the
  /// sink. The port must outlive the bridge or be re-wired first.
  void ConnectTo(BusPort& port);

  ControllerState SocketCanState() const { return tracker_.State(); }
  void OnSocketCanStateChange(BusPort::StateHandler handler) { on_state_ = std::move(handler); }
  void OnError(SocketCanSocket::ErrorHandler handler) { on_error_ = std::move(handler); }

  const Stats& BridgeStats() const { return stats_; }
  const SocketCanStats& SocketStats() const { return socket_.Stats(); }
  const std::string& Interface() const { return socket_.Interface(); }

 private:
  static SocketCanOptions BridgeOptions(SocketCanOptions options);
  void OnBatch(std::span<const CanFrame> frames);

  VirtualBusSink to_virtual_bus_;
  BusPort::StateHandler on_state_;
  SocketCanSocket::ErrorHandler on_error_;
  ControllerStateTracker tracker_;
  Stats stats_;
  std::shared_ptr<int> alive_ = std::make_shared<int>(0);
  SocketCanSocket socket_;  // last: destroyed first
};

}  // namespace canfleet
