#pragma once
/// @file The fault stage of one bus: rules applied between arbitration and delivery, plus direct
/// controller faults. The fault looks to every node as it would on a real bus (design decision 3):
/// a dropped heartbeat is simply never seen; a corrupted frame is an error frame on the wire with
/// its error-counter consequences.

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
}

enum class FaultAction : std::uint8_t {
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

const char* ToString(FaultAction action);

/// One rule. A rule applies to a transfer whose start of frame lies within its lifetime (from the
/// scheduler time at which it was added), sent by `source`, whose identifier matches `id` under
/// `mask`, of the given format; it then fires with `probability`.
struct FaultRule {
  std::optional<PortId> source{};   ///< only frames sent by this port; nullopt = any port
  std::uint32_t id = 0;             ///< compared with the frame's identifier under `mask`
  std::uint32_t mask = 0;           ///< 0 matches every identifier; 0x7FF with id 0x705 = exactly 705h
  std::optional<bool> extended{};   ///< only 29-bit (true) or 11-bit (false) frames; nullopt = both
  std::vector<PortId> receivers{};  ///< kDrop/kDelay: the receivers affected; empty = every receiver

  FaultAction action = FaultAction::kDrop;
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
  /// `bus` performs the direct controller faults (ForceBusOff, HoldErrorPassive, StartBabbling) on its
  /// ports; the bus owns its stage.
  FaultStage(Scheduler& scheduler, detail::VirtualBus& bus);

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
  friend class detail::VirtualBus;

  struct Rule {
    RuleId id = 0;
    FaultRule spec;
    BusTime added{};
    std::optional<BusTime> expires;
    std::optional<std::uint64_t> remaining;
    std::uint64_t hits = 0;
    std::uint64_t rng = 0;  ///< splitmix64 state
  };

  /// What one receiver gets.
  struct Decision {
    enum Kind : std::uint8_t { kDeliver, kDrop, kDelay } kind = kDeliver;
    Duration delay{};
  };

  // ---- the broker's side, all on the bus time line ----
  bool Empty() const { return rules_.empty(); }
  /// At start of frame: true when a corrupt rule fires on this transfer attempt.
  bool CorruptAttempt(PortId source, const CanFrame& frame, BusTime start);
  /// At end of an acknowledged transfer: evaluates drop/delay/duplicate rules once. Returns true
  /// when the transfer is to be repeated (kDuplicate). `repetition` marks a repeated transfer.
  bool EvaluateDelivery(PortId source, const CanFrame& frame, BusTime start, bool repetition);
  /// After EvaluateDelivery: what `receiver` gets.
  Decision ForReceiver(PortId receiver);
  /// After the receivers were served: forgets the fired set, removes rules that are used up or
  /// expired at `start` (starts of frame only move forward on a bus).
  void EndOfTransfer(BusTime start);

  static bool Matches(const Rule& rule, PortId source, const CanFrame& frame, BusTime start);
  static bool Fires(Rule& rule);
  void Sweep(BusTime now);

  Scheduler& scheduler_;
  detail::VirtualBus& bus_;
  std::vector<Rule> rules_;
  std::vector<std::size_t> fired_;  ///< indexes into rules_ of drop/delay rules fired on this transfer
  RuleId next_id_ = 1;
};

}  // namespace canfleet::broker
