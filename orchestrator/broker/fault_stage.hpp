#pragma once
/// @file The fault stage of one bus, its public face: rules applied between arbitration and
/// delivery, plus direct controller faults. The fault looks to every node as it would on a real bus
/// (design decision 3): a dropped heartbeat is simply never seen; a corrupted frame is an error
/// frame on the wire with its error-counter consequences.
///
/// Who does what: the rules decide (fault_rules.hpp: which transfer is corrupted, which receiver
/// misses or gets a frame late, knowing nothing of the bus); the bus acts on those decisions and
/// performs the controller faults (virtual_bus.hpp). This class only forwards to them.

#include <chrono>
#include <cstdint>
#include <optional>
#include <vector>

#include "bus/bus_port.hpp"
#include "bus/can_frame.hpp"
#include "clock/scheduler.hpp"
#include "orchestrator/broker/port_sink.hpp"

namespace canfleet::broker {

namespace detail {
class VirtualBus;
class FaultRules;
}  // namespace detail

/// What a FaultRule does to a transfer it fires on. (Not telemetry::FaultAction, which says
/// whether a fault of the fleet began or ended.)
enum class RuleAction : std::uint8_t {
  /// The matched receivers never see the frame. The transfer itself succeeded on the wire: the
  /// sender gets its TX confirmation and every receiver's REC still decreases.
  kDrop,
  /// The matched receivers see the frame `delay` plus a uniformly drawn 0..`jitter` after its end
  /// of frame, stamped with that later time. Without jitter, delayed frames keep their order
  /// relative to each other (and to undelayed frames of the same receiver when the delay is not
  /// longer than the gap between frames); with jitter, frames to one receiver can be reordered.
  kDelay,
  /// The transfer is destroyed by an error frame (modelled as a CRC error, see wire_model.hpp):
  /// nobody receives it, the sender's TEC rises by 8 and it retransmits automatically, every
  /// receiver's REC rises by 1 (ISO 11898-1:2015 §6.11 automatic retransmission, §12.1.4 rules).
  /// Acts on the wire, so `receivers` is ignored. 32 corrupted attempts in a row take an
  /// error-active sender bus-off.
  kCorrupt,
  /// The transfer is repeated once on the wire (CAN's double reception, as when the transmitter
  /// sees an error in the last bit of end-of-frame after the receivers accepted the frame): every
  /// receiver gets the frame twice, the copy with its own later bus time; the sender gets one TX
  /// confirmation. The repetition is not matched by duplicate rules again. Acts on the wire, so
  /// `receivers` is ignored.
  kDuplicate,
};

const char* ToString(RuleAction action);

/// One rule. A rule applies to a transfer whose start of frame lies within its lifetime (from the
/// scheduler time at which it was added), sent by `source`, whose identifier matches `id` under
/// `mask`, of the given format; it then fires with `probability`.
struct FaultRule {
  std::optional<PortId> source{};   ///< only frames sent by this port; nullopt = any port
  std::uint32_t id = 0;             ///< compared with the frame's identifier under `mask`
  std::uint32_t mask = 0;           ///< 0 matches every identifier; 0x7FF with id 0x705 = exactly 705h
  std::optional<bool> extended{};   ///< only 29-bit (true) or 11-bit (false) frames; nullopt = both
  std::vector<PortId> receivers{};  ///< kDrop/kDelay: the receivers affected; empty = every receiver

  RuleAction action = RuleAction::kDrop;
  Duration delay{};   ///< kDelay: fixed part
  Duration jitter{};  ///< kDelay: random extra in [0, jitter], drawn per receiver

  /// Chance that a matching transfer is affected, drawn once per transfer from a generator seeded
  /// with `seed`: the same rules, seeds and traffic give the same faults on every run.
  double probability = 1.0;
  std::uint64_t seed = 0;

  std::optional<Duration> lifetime{};    ///< expires this long after being added; nullopt = no limit
  std::optional<std::uint64_t> count{};  ///< expires after firing this many times; nullopt = no limit
};

using RuleId = std::uint32_t;

/// A rule as listed.
struct RuleStatus {
  RuleId id = 0;
  FaultRule rule;
  std::uint64_t hits = 0;                  ///< transfers it has fired on
  std::optional<std::uint64_t> remaining;  ///< firings left when `count` was set
  std::optional<TimePoint> expires;        ///< when `lifetime` was set
};

/// The fault stage of one bus (Broker::Faults). Rules are evaluated in the order they were added;
/// for each receiver the first fired drop/delay rule that covers it decides. Everything happens on
/// the bus's own time line, so a rule added while the broker catches up with a late timer does not
/// reach back to transfers that started before it was added.
class FaultStage {
 public:
  /// The bus owns its stage, its rules and its ports.
  FaultStage(const Scheduler& scheduler, detail::FaultRules& rules, detail::VirtualBus& bus)
      : scheduler_(scheduler), rules_(rules), bus_(bus) {}

  /// Adds a rule; returns its id (never reused on this bus). Throws std::invalid_argument when the
  /// probability is not within 0..1, a duration is negative, the lifetime is not positive or the
  /// count is 0.
  RuleId Add(FaultRule rule);
  /// Removes one rule; false if there is no such (live) rule.
  bool Remove(RuleId id);
  /// Removes every rule.
  void Clear();
  /// The live rules (expired ones are not listed), in evaluation order.
  std::vector<RuleStatus> List() const;

  // ---- Direct controller faults ------------------------------------------------------------
  // Each applies now, before any transfer that would start at this same instant (the bus first
  // catches up to now). Each throws std::invalid_argument when the port is not on this bus.

  /// The port goes bus-off now (TEC 256) and its TX queue is dropped. Without `hold` it recovers
  /// like after any bus-off (after 1408 bit times when the bus auto-recovers, else on
  /// Broker::RecoverBusOff). With `hold` it stays bus-off until Broker::RecoverBusOff, whatever the
  /// bus's auto_recover says; the hold ends with that recovery. Returns false when there was
  /// nothing to do: already bus-off, and (with `hold`) already held. Holding a port that is
  /// already bus-off cancels its pending automatic recovery.
  bool ForceBusOff(PortId port, bool hold = false);

  /// A cause that keeps the port bus-off, as a shorted transceiver or a wiring fault at the node
  /// would (`on`), or its end. On: the port goes bus-off now (TEC 256, queue dropped) unless it
  /// already is, and while the cause lasts every recovery attempt fails: the automatic attempts
  /// (1408 bit times after the bus-off, then every 1408 bit times, on a bus that recovers by
  /// itself) are counted in PortStats::failed_recoveries and leave it bus-off, and
  /// Broker::RecoverBusOff returns false (also counted). Its state and TEC stay visible in
  /// PortStats throughout. Off: the cause is gone and the next attempt succeeds (the next automatic
  /// one, or RecoverBusOff). Returns false when the cause already was in that state.
  bool HoldBusOff(PortId port, bool on);

  /// Holds the port's controller error-passive (`on`) or releases it; see
  /// FaultConfinement::HoldErrorPassive for the counters: on = TEC ≥ 128 from now on, the port is
  /// told it is error-passive at once; successes never bring it back, errors still take it
  /// bus-off. Off = TEC set to min(TEC, 127), the port is told it is error-active again (unless
  /// its REC ≥ 128 or it is bus-off). Returns false when the hold already was in that state.
  bool HoldErrorPassive(PortId port, bool on);

  /// The "babbling idiot": from now on the port's controller offers `frame` in every arbitration,
  /// ahead of the port's own TX queue (its TX buffer is stuck with that frame), so it floods the
  /// bus at the full rate the bus allows, taking every arbitration it can win. Others see normal
  /// frames; error confinement and fault rules apply as for any of its frames; the port's sink
  /// gets no TX confirmation for them (the node did not send them) and PortStats::babble_frames
  /// counts them. The port's own frames wait in its queue (and overflow into queue_drops) until
  /// StopBabbling. Calling it again replaces the frame. It survives bus-off (a bus-off controller
  /// sends nothing; after recovery it babbles again).
  ///
  /// Paced buses only: an unpaced bus has no time line, so "full rate" would mean an endless
  /// stream in zero time. Throws std::invalid_argument on an unpaced bus or an invalid or error
  /// frame. Returns false for a listen-only port (it never transmits).
  bool StartBabbling(PortId port, const CanFrame& frame);
  /// Ends StartBabbling; a babble frame already on the wire completes. False when not babbling.
  bool StopBabbling(PortId port);

 private:
  const Scheduler& scheduler_;
  detail::FaultRules& rules_;
  detail::VirtualBus& bus_;
};

}  // namespace canfleet::broker
