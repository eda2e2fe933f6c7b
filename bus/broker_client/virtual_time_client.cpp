#include "bus/broker_client/virtual_time_client.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>

namespace canfleet {

VirtualTimeClient::VirtualTimeClient(GrantedScheduler& scheduler, std::string clock_id,
                                     std::size_t port_count)
    : scheduler_(scheduler), clock_id_(std::move(clock_id)), ports_(std::max<std::size_t>(port_count, 1)) {}

std::uint64_t VirtualTimeClient::Attaching(std::size_t index) {
  Slot& slot = ports_.at(index);
  slot = Slot{};
  slot.attachment = next_attachment_++;
  return slot.attachment;
}

void VirtualTimeClient::Connected(std::size_t index, GrantedPort& port, TimePoint now) {
  Slot& slot = ports_.at(index);
  const std::uint64_t attachment = slot.attachment != 0 ? slot.attachment : next_attachment_++;
  slot = Slot{};
  slot.attachment = attachment;
  slot.port = &port;
  scheduler_.AdvanceTo(now);
  // A grant read on another port may be waiting for this one (see RunIfAllGranted); its own grant,
  // which follows its HelloReply, runs the round.
}

void VirtualTimeClient::Disconnected(std::size_t index) {
  ports_.at(index) = Slot{};
  RunIfAllGranted();  // the others may have been waiting for this one
}

void VirtualTimeClient::Granted(std::size_t index, TimePoint now, TimePoint until,
                                std::span<const std::uint64_t> attachments) {
  Slot& slot = ports_.at(index);
  if (slot.port == nullptr) return;  // a grant follows the HelloReply on its connection
  slot.now = now;
  slot.until = until;
  slot.listed.assign(attachments.begin(), attachments.end());
  RunIfAllGranted();
}

bool VirtualTimeClient::Awaited(const Slot& slot) const {
  if (slot.attachment == 0 || slot.until) return false;  // no open connection, or granted already
  bool named = false;
  for (const Slot& granted : ports_) {
    if (granted.port == nullptr || !granted.until || granted.listed.empty()) continue;
    named = true;
    if (std::ranges::find(granted.listed, slot.attachment) != granted.listed.end()) return true;
  }
  // A broker that names no connections: every connected port.
  return !named && slot.port != nullptr;
}

bool VirtualTimeClient::AnyAcceptanceChanged() {
  bool changed = false;
  for (const std::size_t i : round_)
    changed = (ports_[i].port != nullptr && ports_[i].port->AcceptanceChanged()) || changed;
  return changed;
}

TimePoint VirtualTimeClient::RunUntilFilterChange(TimePoint now, TimePoint until) {
  if (AnyAcceptanceChanged()) {
    ++early_stops_;
    return now;
  }
  while (const auto deadline = scheduler_.NextDeadline()) {
    if (*deadline > until) break;
    scheduler_.AdvanceTo(*deadline);  // every timer of that instant
    if (AnyAcceptanceChanged()) {
      ++early_stops_;
      return scheduler_.Now();
    }
  }
  return until;
}

void VirtualTimeClient::RunIfAllGranted() {
  if (running_) return;
  // The ports of the process are separate connections, read in no set order: a grant may be read
  // on one port while the HelloReply of another, which the broker joined before the same round, is
  // still unread. That port is not connected yet, but its grant is on its way and the broker waits
  // for its TimeReached: running without it left its grant unanswered for good (the broker closed
  // it after the grace, 10 s of real time, and the node missed its first round on that bus). A port
  // whose Hello the broker had not accepted before the round is not granted in it, and must not be
  // waited for (the broker accepts it only once the round ends). Only the broker knows which is
  // which: its grant names the connections of the round (TimeGrant.attachments), and the round
  // waits for each of them still open, whether connected or still waiting for its HelloReply.
  bool any = false;
  for (const Slot& slot : ports_) {
    if (Awaited(slot)) return;
    any = any || (slot.port != nullptr && slot.until);
  }
  if (!any) return;
  std::optional<TimePoint> now, until;
  round_.clear();
  for (std::size_t i = 0; i < ports_.size(); ++i) {
    const Slot& slot = ports_[i];
    if (slot.port == nullptr || !slot.until) continue;
    if (until && *until != *slot.until && !mismatch_logged_) {
      mismatch_logged_ = true;
      spdlog::error(
          "virtual time: the ports of {} were granted different times; the buses of a node in virtual "
          "time must be served by one broker (it runs to the earliest)",
          clock_id_);
    }
    now = now ? std::max(*now, *slot.now) : *slot.now;
    until = until ? std::min(*until, *slot.until) : *slot.until;
    round_.push_back(i);
  }
  ++rounds_;
  running_ = true;
  struct Done {
    bool& flag;
    ~Done() { flag = false; }
  } done{running_};
  scheduler_.AdvanceTo(*now);
  for (const std::size_t i : round_)
    if (ports_[i].port != nullptr) ports_[i].port->ApplyHeld();
  // A grant longer than a frame's travel was made for the filters the broker knows: the node stops
  // at the first instant one of them changed (what it applied at now, or a timer), and the broker
  // grants it again from there with the new one.
  const TimePoint reached = *until - *now > kStopLookahead ? RunUntilFilterChange(*now, *until) : *until;
  scheduler_.AdvanceTo(reached);
  const std::optional<TimePoint> next = scheduler_.NextDeadline();
  scheduler_.TakeOutlook(outlook_);
  if (scheduler_.ConfinementBreaches() > 0 && !breach_logged_) {
    breach_logged_ = true;
    spdlog::error(
        "virtual time: {}: a confined timer armed or woke a timer confined otherwise (Timer::Confine): other "
        "nodes may have been granted past what it does",
        clock_id_);
  }
  for (const std::size_t i : round_) {
    Slot& slot = ports_[i];
    if (slot.port == nullptr) continue;  // lost while the node ran
    slot.now.reset();
    slot.until.reset();
    slot.port->Reached(reached, next, outlook_);
  }
}

}  // namespace canfleet
