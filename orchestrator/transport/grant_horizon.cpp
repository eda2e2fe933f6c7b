#include "orchestrator/transport/grant_horizon.hpp"

#include <algorithm>
#include <utility>

namespace canfleet::transport {

void GrantHorizons::Best2::Add(TimePoint t, std::size_t who) {
  if (t < first) {
    second = first;
    first = t;
    owner = who;
  } else if (t < second) {
    second = t;
  }
}

std::pair<TimePoint, TimePoint> GrantHorizons::ConfinedBound(std::size_t node, std::size_t bus,
                                                             const Acceptance& acceptance) const {
  TimePoint hears = kNever, reacts = kNever;
  const auto ids = acceptance.Ids();
  const auto delays = acceptance.Delays();
  for (std::size_t k = 0; k < ids.size(); ++k) {
    const std::size_t at = bus * kIds + ids[k];
    if (const TimePoint t = table_[at].Except(node); t != kNever) {
      hears = std::min(hears, t);
      reacts = std::min(reacts, t);
    }
    if (const TimePoint t = beats_[at].Except(node); t != kNever) {
      hears = std::min(hears, t);
      reacts = std::min(reacts, t + delays[k]);
    }
  }
  return {hears, reacts};
}

void GrantHorizons::Note(std::size_t bus, std::uint32_t id, TimePoint time, std::size_t owner,
                         bool heartbeat) {
  const std::size_t k = bus * kIds + id;
  if (table_[k].first == kNever && beats_[k].first == kNever) touched_.push_back(k);
  (heartbeat ? beats_ : table_)[k].Add(time, owner);
  noted_[bus].Add(time, owner);
}

void GrantHorizons::Compute(TimePoint now, Duration lookahead, std::optional<TimePoint> cap,
                            std::span<const HorizonBus> buses, std::span<const HorizonNode> nodes,
                            std::span<const KnownFrame> known) {
  const std::size_t n = nodes.size();
  const auto plus = [lookahead](TimePoint t) { return t == kNever ? kNever : t + lookahead; };
  own_.assign(n, kNever);
  active_.assign(n, kNever);
  for (const std::size_t k : touched_)
    table_[k] = beats_[k] = Best2{};
  touched_.clear();
  table_.resize(buses.size() * kIds);
  beats_.resize(buses.size() * kIds);
  noted_.assign(buses.size(), Best2{});
  for (std::size_t i = 0; i < n; ++i) {
    const HorizonNode& node = nodes[i];
    own_[i] = node.any.value_or(node.next.value_or(kNever));
    if (node.pending) own_[i] = std::min(own_[i], now + node.reacts_after);
    active_[i] = node.pending ? now : node.next.value_or(kNever);
    if (own_[i] == now) continue;  // it may answer anything at once: its confined timers add nothing
    for (const HorizonPort& port : node.ports) {
      for (const ConfinedSend& c : node.confined) {
        if (c.time < own_[i] && c.id < kIds) Note(port.bus, c.id, c.time, i, c.heartbeat);
      }
    }
  }
  // Frames sent ahead of the bus reach their listeners from their stamps on; a 29-bit one, or
  // any on a bus that is not calm, may reach anybody there (its sender too: an error).
  anybody_.assign(buses.size(), kNever);
  for (const KnownFrame& f : known) {
    if (f.key < kIds && buses[f.bus].calm)
      Note(f.bus, f.key, f.time, f.owner, f.heartbeat);
    else
      anybody_[f.bus] = std::min(anybody_[f.bus], f.time);
  }

  // What does not depend on when the others may send: the cap, the frames already on the buses,
  // the confined timers of the others (fixed_: when they may reach it; fixed_react_: when they
  // may make it send, a passive heartbeat only after its delay).
  fixed_.assign(n, cap.value_or(kNever));
  fixed_react_.assign(n, cap.value_or(kNever));
  for (std::size_t i = 0; i < n; ++i) {
    for (const HorizonPort& port : nodes[i].ports) {
      const HorizonBus& bus = buses[port.bus];
      const Acceptance& acceptance = *port.acceptance;
      const auto bound = [&](TimePoint hears, TimePoint reacts) {
        fixed_[i] = std::min(fixed_[i], hears);
        fixed_react_[i] = std::min(fixed_react_[i], reacts);
      };
      if (anybody_[port.bus] != kNever) bound(plus(anybody_[port.bus]), plus(anybody_[port.bus]));
      if (bus.next_event) {
        for (const PendingFrame& f : bus.pending) {
          if (!bus.calm || acceptance.AcceptsKey(f.key))
            bound(*bus.next_event,
                  f.heartbeat ? *bus.next_event + acceptance.DelayOf(f.key) : *bus.next_event);
        }
        if (!bus.calm) bound(*bus.next_event, *bus.next_event);
      }
      if (!bus.calm) continue;
      if (acceptance.All()) {
        const TimePoint t = plus(noted_[port.bus].Except(i));
        bound(t, t);
      } else {
        const auto [hears, reacts] = ConfinedBound(i, port.bus, acceptance);
        bound(plus(hears), plus(reacts));
      }
    }
  }

  // The fixed point: a process may send anything from when something may reach it.
  sends_ = own_;
  horizon_.assign(n, kNever);
  passes_ = 0;
  for (bool changed = true; changed && passes_ <= n + 1; ++passes_) {
    any_.assign(buses.size(), Best2{});
    all_.assign(buses.size(), Best2{});
    for (std::size_t i = 0; i < n; ++i) {
      for (const HorizonPort& port : nodes[i].ports) {
        any_[port.bus].Add(sends_[i], i);
        all_[port.bus].Add(std::min(active_[i], sends_[i]), i);
      }
    }
    changed = false;
    for (std::size_t i = 0; i < n; ++i) {
      TimePoint h = kNever;  // what may reach it from what the others may send at once
      for (const HorizonPort& port : nodes[i].ports) {
        const Acceptance& acceptance = *port.acceptance;
        if (!buses[port.bus].calm)
          h = std::min(h, plus(all_[port.bus].first));  // its own frames too: errors, state changes
        else if (acceptance.All())
          h = std::min(h, plus(all_[port.bus].Except(i)));
        else if (!acceptance.Empty())
          h = std::min(h, plus(any_[port.bus].Except(i)));
      }
      horizon_[i] = std::min(fixed_[i], h);
      const TimePoint sends = std::min(own_[i], std::min(fixed_react_[i], h));
      if (sends < sends_[i]) {
        sends_[i] = sends;
        changed = true;
      }
    }
  }
}

}  // namespace canfleet::transport
