#include "orchestrator/broker/fault_rules.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

namespace canfleet::broker::detail {

namespace {

/// splitmix64: tiny, fast and identical on every platform (std::uniform_*_distribution is not), so
/// a seed gives the same faults everywhere.
std::uint64_t NextRandom(std::uint64_t& state) {
  state += 0x9E3779B97F4A7C15ULL;
  std::uint64_t z = state;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

}  // namespace

RuleId FaultRules::Add(FaultRule rule, BusTime now) {
  if (!(rule.probability >= 0.0 && rule.probability <= 1.0))  // also rejects NaN
    throw std::invalid_argument("fault rule: probability must be within 0..1");
  if (rule.delay < Duration::zero() || rule.jitter < Duration::zero())
    throw std::invalid_argument("fault rule: delay and jitter must not be negative");
  if (rule.lifetime && *rule.lifetime <= Duration::zero())
    throw std::invalid_argument("fault rule: lifetime must be positive");
  if (rule.count && *rule.count == 0) throw std::invalid_argument("fault rule: count must be at least 1");

  Rule r;
  r.id = next_id_++;
  r.added = now;
  if (rule.lifetime) r.expires = r.added + *rule.lifetime;
  r.remaining = rule.count;
  r.rng = rule.seed;
  r.spec = std::move(rule);
  rules_.push_back(std::move(r));
  return rules_.back().id;
}

bool FaultRules::Remove(RuleId id) {
  auto it = std::find_if(rules_.begin(), rules_.end(), [id](const Rule& r) { return r.id == id; });
  if (it == rules_.end()) return false;
  rules_.erase(it);
  return true;
}

std::vector<RuleStatus> FaultRules::List(BusTime now) const {
  std::vector<RuleStatus> out;
  for (const Rule& r : rules_) {
    if (r.expires && *r.expires <= now) continue;
    RuleStatus s;
    s.id = r.id;
    s.rule = r.spec;
    s.hits = r.hits;
    s.remaining = r.remaining;
    if (r.expires) s.expires = TimePoint(*r.expires);
    out.push_back(std::move(s));
  }
  return out;
}

bool FaultRules::Matches(const Rule& rule, PortId source, const CanFrame& frame, BusTime start) {
  if (start < rule.added) return false;
  if (rule.expires && start >= *rule.expires) return false;
  if (rule.remaining && *rule.remaining == 0) return false;
  const FaultRule& s = rule.spec;
  if (s.source && *s.source != source) return false;
  if (s.extended && *s.extended != frame.extended()) return false;
  return ((frame.id ^ s.id) & s.mask) == 0;
}

bool FaultRules::Fires(Rule& rule) {
  const double p = rule.spec.probability;
  bool fires = p >= 1.0;
  if (!fires && p > 0.0) {
    // 53 random bits → [0, 1) with full double precision.
    const double u = static_cast<double>(NextRandom(rule.rng) >> 11) * 0x1.0p-53;
    fires = u < p;
  }
  if (!fires) return false;
  ++rule.hits;
  if (rule.remaining) --*rule.remaining;
  return true;
}

void FaultRules::Sweep(BusTime now) {
  std::erase_if(rules_, [now](const Rule& r) {
    return (r.remaining && *r.remaining == 0) || (r.expires && *r.expires <= now);
  });
}

bool FaultRules::CorruptAttempt(PortId source, const CanFrame& frame, BusTime start) {
  bool corrupt = false;
  for (Rule& r : rules_) {
    if (r.spec.action != RuleAction::kCorrupt || !Matches(r, source, frame, start)) continue;
    if (Fires(r)) {
      corrupt = true;
      break;
    }
  }
  Sweep(start);
  return corrupt;
}

bool FaultRules::EvaluateDelivery(PortId source, const CanFrame& frame, BusTime start, bool repetition) {
  fired_.clear();
  bool duplicate = false;
  for (std::size_t i = 0; i < rules_.size(); ++i) {
    Rule& r = rules_[i];
    const RuleAction action = r.spec.action;
    if (action == RuleAction::kCorrupt) continue;
    if (action == RuleAction::kDuplicate && (repetition || duplicate)) continue;
    if (!Matches(r, source, frame, start) || !Fires(r)) continue;
    if (action == RuleAction::kDuplicate)
      duplicate = true;
    else
      fired_.push_back(i);
  }
  return duplicate;
}

FaultRules::Decision FaultRules::ForReceiver(PortId receiver) {
  for (std::size_t i : fired_) {
    Rule& r = rules_[i];
    const auto& receivers = r.spec.receivers;
    if (!receivers.empty() && std::find(receivers.begin(), receivers.end(), receiver) == receivers.end())
      continue;
    if (r.spec.action == RuleAction::kDrop) return {Decision::kDrop, {}};
    Duration delay = r.spec.delay;
    if (r.spec.jitter > Duration::zero()) {
      const auto span = static_cast<std::uint64_t>(r.spec.jitter.count()) + 1;
      delay += Duration(static_cast<Duration::rep>(NextRandom(r.rng) % span));
    }
    return {Decision::kDelay, delay};
  }
  return {};
}

void FaultRules::EndOfTransfer(BusTime start) {
  fired_.clear();
  Sweep(start);
}

}  // namespace canfleet::broker::detail
