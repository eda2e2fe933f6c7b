#pragma once
/// @file The broker's side of a port: what it hands to whatever carries that port's traffic (a
/// TCP/Unix session, a socketcand session, the SocketCAN bridge, a test).

#include <cstdint>
#include <span>

#include "bus/bus_port.hpp"
#include "bus/can_frame.hpp"

namespace canfleet::broker {

/// Names one attachment (a node or a tool) to one bus. Never reused within a Broker; 0 is never
/// a valid id.
using PortId = std::uint32_t;

/// A frame with the time it happened. Paced buses: bus time at the end of the frame (the end of
/// the intermission that follows it, so back-to-back frames tile the time line); a delayed frame
/// (fault stage) carries the time it is delivered. Unpaced buses: the broker time at which the
/// frame was submitted.
struct TimedFrame {
  CanFrame frame;
  BusTime time;
};

/// Implemented by transports. The broker calls it from the thread that drives its scheduler, never
/// re-entrantly for one port, and only after the bus's state for that round is consistent, so a
/// sink may call back into the Broker (Submit, Detach, ...) from inside any of these.
///
/// Order: each call covers the events of one processing round. Within a port, frames, TX
/// confirmations and controller events arrive in bus order, except that the Deliver and
/// TxConfirmed batches of one span between two controller events are two calls (Deliver first).
class PortSink {
 public:
  virtual ~PortSink() = default;
  /// Frames sent by other ports, in bus order, with non-decreasing times. One call per round; the
  /// span is only valid during the call.
  virtual void Deliver(std::span<const TimedFrame> frames) = 0;
  /// This port's controller changed state (error-active / error-passive / bus-off), with the
  /// counters at that moment.
  virtual void ControllerChanged(const ControllerEvent& event) = 0;
  /// This port's own frames that won arbitration and were acknowledged, with their bus times.
  virtual void TxConfirmed(std::span<const TimedFrame> frames) { (void)frames; }
};

}  // namespace canfleet::broker
