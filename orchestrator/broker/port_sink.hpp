#pragma once
/// @file The broker's side of a port: what it hands to whatever carries that port's traffic (a
/// TCP/Unix session, a socketcand session, the SocketCAN bridge, a test).

#include <cstdint>
#include <span>
#include <vector>

#include "bus/bus_port.hpp"
#include "bus/can_frame.hpp"

namespace canfleet::broker {

namespace detail {
class VirtualBus;
}

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

/// Indexes [begin, end) into SharedRound::Frames().
struct FrameRun {
  std::uint32_t begin = 0;
  std::uint32_t end = 0;
  std::uint32_t size() const { return end - begin; }
};

/// Every frame one processing round of one bus produced, in bus order, written once for all the
/// ports of the bus (issue 4: a frame to 31 receivers is not copied 31 times). Each port receives
/// runs of it: the round minus its own frames and minus the per-receiver exceptions of the fault
/// stage, plus what is addressed to it alone (a delayed frame, an error frame for a monitor).
class SharedRound {
 public:
  /// The whole round, including frames a given port does not receive. Stable while sinks run.
  std::span<const TimedFrame> Frames() const { return {frames_.data(), frames_.size()}; }
  /// Never the same for two rounds of any bus in this process (a sink may cache what it derives
  /// from Frames(), e.g. an encoding shared by every session, under this key). Never 0.
  std::uint64_t Id() const { return id_; }

  /// The frames of `runs`, contiguous: a view into Frames() for a single run, else a copy in a
  /// buffer of this round (valid until the next Gather or the end of the sink call).
  std::span<const TimedFrame> Gather(std::span<const FrameRun> runs) const;

 private:
  friend class detail::VirtualBus;
  std::vector<TimedFrame> frames_;
  std::uint64_t id_ = 0;
  mutable std::vector<TimedFrame> gathered_;
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
  /// The same frames as Deliver, as `runs` (non-empty, ascending, none empty) of the round shared
  /// by every port of the bus. The broker calls this one; the default gathers the runs (no copy
  /// for a single run) and calls Deliver. A sink that can use the shared round directly (the
  /// TCP/Unix session encodes it once for all sessions) overrides it.
  virtual void DeliverShared(const SharedRound& round, std::span<const FrameRun> runs) {
    Deliver(round.Gather(runs));
  }
  /// This port's controller changed state (error-active / error-passive / bus-off), with the
  /// counters at that moment.
  virtual void ControllerChanged(const ControllerEvent& event) = 0;
  /// This port's own frames that won arbitration and were acknowledged, with their bus times.
  virtual void TxConfirmed(std::span<const TimedFrame> frames) { (void)frames; }
};

inline std::span<const TimedFrame> SharedRound::Gather(std::span<const FrameRun> runs) const {
  if (runs.empty()) return {};
  if (runs.size() == 1) return Frames().subspan(runs[0].begin, runs[0].size());
  gathered_.clear();
  for (const FrameRun& run : runs)
    gathered_.insert(gathered_.end(), frames_.begin() + run.begin, frames_.begin() + run.end);
  return {gathered_.data(), gathered_.size()};
}

}  // namespace canfleet::broker
