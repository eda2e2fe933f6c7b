#pragma once
/// @file The in-process broker: named virtual CAN buses, ports attached to them, and the wire's
/// physics between them (design decision 3: arbitration by identifier, exact frame durations, bus
/// load, error counters and bus-off live here, not in the nodes). Transports (TCP/Unix sessions,
/// socketcand, the SocketCAN bridge) attach a PortSink per connection and Submit what it sends.
///
/// Threading: not thread-safe. Every call, and every timer of the Scheduler, runs on the thread of
/// that scheduler's event loop; sinks are called from there too.

#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "bus/can_frame.hpp"
#include "clock/scheduler.hpp"
#include "orchestrator/broker/bus_config.hpp"
#include "orchestrator/broker/fault_stage.hpp"
#include "orchestrator/broker/port_sink.hpp"
#include "orchestrator/broker/stats.hpp"

namespace canfleet::broker {

namespace detail {
class VirtualBus;
struct Port;
}  // namespace detail

/// What a bus can still bring its receivers by itself (lock-step virtual time, issue 34:
/// TimeConductor grants each node process as far as nothing it listens to can reach it).
struct BusOutlook {
  /// No transfer can fail and no controller can change state by itself: every attached port runs
  /// at the bus's rate and is error-active (or bus-off with no recovery due), none babbles, at
  /// least two can acknowledge, and no fault rule corrupts. Then a port receives only the frames
  /// others send, and nothing of its own ones.
  bool calm = false;
  std::optional<TimePoint> next_event;  ///< the bus's next event (a transfer ends, ...)
  /// Frames on the bus (in flight, queued, delayed by a fault). Each reaches its receivers at
  /// the next event or later.
  std::vector<CanFrame> frames;
  std::size_t transmitters = 0;  ///< attached ports that may transmit (not listen-only)
};

/// Paced buses (the default) model the wire on the bus's own time line:
/// - the head frames of all ports' TX queues (FIFO per port) are arbitrated by ArbitrationKey;
///   a frame joins an arbitration when it was submitted by the arbitration's start, so frames
///   submitted at the same instant compete and a frame submitted during a transfer waits for it;
/// - a transfer occupies the bus for CountFrameBits(frame).total() bit times (an idle bus starts
///   it when it is submitted); every other port receives it and the sender gets a TX
///   confirmation, both stamped with the end-of-frame bus time;
/// - error confinement per port (the rules of bus/physics/): TEC/REC on success, ACK errors and
///   retransmission for a port alone on the bus (it stops at error-passive), bus-off, recovery
///   after 1408 bit times or on command;
/// - the fault stage (Faults) sits between arbitration and delivery.
/// When the scheduler's timer fires late (real time), every event due by then is processed in one
/// round with the times it would have had; each port then gets one batch.
///
/// Unpaced buses have no time line: frames go in submission order (FIFO across ports), take no
/// time and carry their submission time; delivery is batched per round (a zero-delay timer).
class Broker {
 public:
  explicit Broker(Scheduler& scheduler);
  ~Broker();
  Broker(const Broker&) = delete;
  Broker& operator=(const Broker&) = delete;

  /// Creates a bus. Throws std::invalid_argument on an empty or duplicate name, a bitrate
  /// outside 10 000..1 000 000, a TX queue capacity of 0 or a non-positive statistics window.
  void AddBus(const BusConfig& config);

  /// Attaches a port to `bus`. `sink` must stay valid until Detach. Throws std::invalid_argument
  /// on an unknown bus or an AttachOptions::bitrate outside 10 000..1 000 000 (0 = the bus's).
  PortId Attach(std::string_view bus, std::string port_name, PortSink& sink, AttachOptions options = {});

  /// Detaches a port: its queue is discarded and its sink is never called again (also when called
  /// from inside that sink). A frame of the port already on the wire completes for the receivers.
  /// False for an unknown or already detached port.
  bool Detach(PortId port);

  /// Queues frames for arbitration (paced) or for the next round (unpaced); returns how many
  /// were accepted. Dropped and counted: invalid frames (PortStats::invalid_drops), frames sent
  /// while bus-off (bus_off_drops), frames beyond the TX queue capacity (queue_drops).
  /// An unknown or detached port is ignored (0): a transport may race with Detach.
  std::size_t Submit(PortId port, std::span<const CanFrame> frames);
  std::size_t Submit(PortId port, const CanFrame& frame) { return Submit(port, std::span(&frame, 1)); }

  /// Bus-off recovery on command (like `ip link set can0 type can restart`): the port becomes
  /// error-active now with TEC = REC = 0 (error-passive with TEC 128 while
  /// FaultStage::HoldErrorPassive holds it). Ends a FaultStage::ForceBusOff hold. False when it is
  /// not bus-off or unknown, and while FaultStage::HoldBusOff holds it (the attempt fails).
  bool RecoverBusOff(PortId port);

  /// The port's controller now runs at `bitrate` bit/s (0 = its bus's rate), as after CiA 305
  /// "activate bit timing": from now on it exchanges frames only with the ports at that rate and
  /// sees the others' as error frames (README "Bit rate"). Its counters, state and queue stay. False
  /// for an unknown or detached port; throws std::invalid_argument on a rate outside
  /// 10 000..1 000 000.
  bool SetPortBitrate(PortId port, std::uint32_t bitrate);

  /// The fault stage of a bus. Throws std::invalid_argument on an unknown bus.
  FaultStage& Faults(std::string_view bus);

  /// Throws std::invalid_argument on an unknown bus. `top_ids`: how many identifiers to list.
  BusStats Stats(std::string_view bus, std::size_t top_ids = 10) const;
  /// Throws std::invalid_argument on an unknown or detached port.
  PortStats Port(PortId port) const;
  /// Every attached port of a bus, in attach order. Throws on an unknown bus.
  std::vector<PortStats> Ports(std::string_view bus) const;
  /// The newest attached port of `bus` called `name` (a node that reconnects may briefly have
  /// two), or nullopt. Throws on an unknown bus.
  std::optional<PortId> NewestPortNamed(std::string_view bus, std::string_view name) const;
  /// Bus names in the order they were added.
  std::vector<std::string> Buses() const;
  /// Fills `out` (reusing its storage). Throws std::invalid_argument on an unknown bus.
  void Outlook(std::string_view bus, BusOutlook& out) const;
  /// The confinement (Timer::Confine) of every bus's timer: its callbacks only run the bus, whose
  /// effects Outlook describes.
  static constexpr std::uint32_t kBusTimerKey = 0xFFFF'FFFE;

 private:
  struct PortRef {
    detail::VirtualBus* bus = nullptr;
    detail::Port* port = nullptr;
  };
  detail::VirtualBus& FindBus(std::string_view name) const;
  const PortRef* FindPort(PortId id) const;

  Scheduler& scheduler_;
  std::vector<std::unique_ptr<detail::VirtualBus>> buses_;
  std::vector<PortRef> ports_;  ///< indexed by PortId; entry 0 unused, detached entries empty
};

}  // namespace canfleet::broker
