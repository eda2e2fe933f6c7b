#pragma once
/// @file The one seam between a CANopen stack and whatever carries its frames (broker, SocketCAN, tests).

#include <chrono>
#include <cstdint>
#include <functional>

#include "bus/can_frame.hpp"

namespace canfleet {

/// ISO 11898-1 fault confinement states of a CAN controller.
enum class ControllerState : std::uint8_t { kErrorActive, kErrorPassive, kBusOff };

const char* ToString(ControllerState state);

/// A change of the controller's fault-confinement state, with the counters that caused it.
struct ControllerEvent {
  ControllerState state = ControllerState::kErrorActive;
  std::uint16_t tec = 0;  ///< transmit error counter (may exceed 255 in bus-off)
  std::uint8_t rec = 0;   ///< receive error counter
};

/// Bus time of a received frame: nanoseconds on the bus's own time line (end of frame); 0 if unknown.
using BusTime = std::chrono::nanoseconds;

/// A node's attachment to one CAN bus. Implementations: the broker client (TCP/Unix socket),
/// SocketCAN, and LoopbackBus for unit tests. The stack never knows which one it talks to.
///
/// Threading: handlers are invoked on the thread that drives the port (the node's event loop),
/// never concurrently with each other.
class BusPort {
 public:
  using ReceiveHandler = std::function<void(const CanFrame&, BusTime)>;
  using StateHandler = std::function<void(const ControllerEvent&)>;

  virtual ~BusPort() = default;

  /// Queues a frame for transmission. Returns false if the frame is invalid, the controller is
  /// bus-off or the transmit queue is full; the frame is then dropped (as a CAN driver would).
  virtual bool Send(const CanFrame& frame) = 0;

  /// The current fault-confinement state.
  virtual ControllerState State() const = 0;

  /// The controller switches to `bit_per_s` (CiA 305 activate bit timing, a device's bit-rate
  /// object at reset). True when the port follows: from now on it takes part in the bus at that
  /// rate (the broker client tells the broker; a node at another rate than its bus's then sees
  /// error frames and no traffic, orchestrator/broker/README.md "Bit rate"). False when the rate
  /// is not the port's to set (SocketCAN: the interface's, `ip link set ... bitrate`; a test
  /// loopback): the caller says so.
  virtual bool SetBitRate(std::uint32_t bit_per_s) {
    (void)bit_per_s;
    return false;
  }

  /// What the node listens to changed outside an answer to a command (a power supply falling
  /// asleep wakes on any frame): a port with an acceptance filter sends the new one now.
  virtual void AcceptanceMayHaveChanged() {}

  void OnReceive(ReceiveHandler handler) { receive_ = std::move(handler); }
  void OnStateChange(StateHandler handler) { state_change_ = std::move(handler); }

 protected:
  void Deliver(const CanFrame& frame, BusTime time) {
    if (receive_) receive_(frame, time);
  }
  void NotifyState(const ControllerEvent& event) {
    if (state_change_) state_change_(event);
  }

 private:
  ReceiveHandler receive_;
  StateHandler state_change_;
};

}  // namespace canfleet
