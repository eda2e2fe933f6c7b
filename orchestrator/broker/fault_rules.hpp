#pragma once
/// @file The fault rules of one bus and what they decide for each transfer (internal: FaultStage
/// is the public face). Rules only decide; the bus acts on the decisions (VirtualBus). Nothing here
/// knows the bus, its ports or a clock: every call is given the bus time it is about.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "bus/can_frame.hpp"
#include "orchestrator/broker/fault_stage.hpp"
#include "orchestrator/broker/port_sink.hpp"

namespace canfleet::broker::detail {

class FaultRules {
 public:
  /// What one receiver of an acknowledged transfer gets.
  struct Decision {
    enum Kind : std::uint8_t { kDeliver, kDrop, kDelay } kind = kDeliver;
    Duration delay{};
  };

  FaultRules() { fired_.reserve(16); }

  /// See FaultStage::Add; `now` is when it was added (bus time).
  RuleId Add(FaultRule rule, BusTime now);
  bool Remove(RuleId id);
  void Clear() { rules_.clear(); }
  /// The rules live at `now`.
  std::vector<RuleStatus> List(BusTime now) const;

  bool Empty() const { return rules_.empty(); }
  /// Some rule may destroy a transfer (kCorrupt): then errors and controller events may follow.
  bool MayCorrupt() const {
    for (const Rule& rule : rules_)
      if (rule.spec.action == RuleAction::kCorrupt) return true;
    return false;
  }

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

 private:
  struct Rule {
    RuleId id = 0;
    FaultRule spec;
    BusTime added{};
    std::optional<BusTime> expires;
    std::optional<std::uint64_t> remaining;
    std::uint64_t hits = 0;
    std::uint64_t rng = 0;  ///< splitmix64 state
  };

  static bool Matches(const Rule& rule, PortId source, const CanFrame& frame, BusTime start);
  static bool Fires(Rule& rule);
  void Sweep(BusTime now);

  std::vector<Rule> rules_;
  std::vector<std::size_t> fired_;  ///< indexes into rules_ of drop/delay rules fired on this transfer
  RuleId next_id_ = 1;
};

}  // namespace canfleet::broker::detail
