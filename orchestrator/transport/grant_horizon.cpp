#include "orchestrator/transport/grant_horizon.hpp"

#include <algorithm>
#include <tuple>

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

TimePoint GrantHorizons::ConfinedBound(std::size_t node, std::size_t bus,
                                       const Acceptance& acceptance) const {
  TimePoint earliest = kNever;
  for (const std::uint32_t id : acceptance.Ids()) {
    auto it = std::lower_bound(confined_.begin(), confined_.end(), std::pair(bus, id),
                               [](const Confined& c, const std::pair<std::size_t, std::uint32_t>& key) {
                                 return std::tie(c.bus, c.id) < std::tie(key.first, key.second);
                               });
    for (; it != confined_.end() && it->bus == bus && it->id == id; ++it) {
      if (it->owner == node) continue;
      earliest = std::min(earliest, it->time);  // sorted by time: the first of another is the earliest
      break;
    }
  }
  return earliest;
}

void GrantHorizons::Compute(TimePoint now, Duration lookahead, std::optional<TimePoint> cap,
                            std::span<const HorizonBus> buses, std::span<const HorizonNode> nodes) {
  const std::size_t n = nodes.size();
  const auto plus = [lookahead](TimePoint t) { return t == kNever ? kNever : t + lookahead; };
  own_.assign(n, kNever);
  active_.assign(n, kNever);
  confined_.clear();
  for (std::size_t i = 0; i < n; ++i) {
    const HorizonNode& node = nodes[i];
    own_[i] = node.pending ? now : node.any.value_or(node.next.value_or(kNever));
    active_[i] = node.pending ? now : node.next.value_or(kNever);
    if (node.pending) continue;  // it may answer anything at once: its confined timers add nothing
    for (const HorizonPort& port : node.ports)
      for (const ConfinedSend& c : node.confined)
        if (c.time < own_[i]) confined_.push_back({port.bus, c.id, c.time, i});
  }
  std::sort(confined_.begin(), confined_.end(), [](const Confined& a, const Confined& b) {
    return std::tie(a.bus, a.id, a.time, a.owner) < std::tie(b.bus, b.id, b.time, b.owner);
  });

  // What does not depend on when the others may send: the cap, the frames already on the buses,
  // the confined timers of the others.
  fixed_.assign(n, cap.value_or(kNever));
  for (std::size_t i = 0; i < n; ++i) {
    for (const HorizonPort& port : nodes[i].ports) {
      const HorizonBus& bus = buses[port.bus];
      const Acceptance& confined = port.Confined();
      if (bus.next_event && (!bus.calm || (port.boot_ups && bus.boot_up) ||
                             std::ranges::any_of(bus.pending_keys, [&](std::uint32_t key) {
                               return confined.AcceptsKey(key);
                             })))
        fixed_[i] = std::min(fixed_[i], *bus.next_event);
      if (bus.calm && !confined.All())
        fixed_[i] = std::min(fixed_[i], plus(ConfinedBound(i, port.bus, confined)));
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
      TimePoint h = fixed_[i];
      for (const HorizonPort& port : nodes[i].ports) {
        const Acceptance& acceptance = *port.acceptance;
        if (!buses[port.bus].calm)
          h = std::min(h, plus(all_[port.bus].first));  // its own frames too: errors, state changes
        else if (acceptance.All())
          h = std::min(h, plus(all_[port.bus].Except(i)));
        else if (!acceptance.Empty())
          h = std::min(h, plus(any_[port.bus].Except(i)));
      }
      horizon_[i] = h;
      const TimePoint sends = std::min(own_[i], h);
      if (sends < sends_[i]) {
        sends_[i] = sends;
        changed = true;
      }
    }
  }
}

}  // namespace canfleet::transport
