#include "bus/broker_client/virtual_time_client.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>

namespace canfleet {

VirtualTimeClient::VirtualTimeClient(GrantedScheduler& scheduler, std::string clock_id,
                                     std::size_t port_count)
    : scheduler_(scheduler), clock_id_(std::move(clock_id)), ports_(std::max<std::size_t>(port_count, 1)) {}

void VirtualTimeClient::Connected(std::size_t index, GrantedPort& port, TimePoint now) {
  Slot& slot = ports_.at(index);
  slot = Slot{&port, std::nullopt, std::nullopt};
  scheduler_.AdvanceTo(now);
}

void VirtualTimeClient::Disconnected(std::size_t index) {
  ports_.at(index) = Slot{};
  RunIfAllGranted();  // the others may have been waiting for this one
}

void VirtualTimeClient::Granted(std::size_t index, TimePoint now, TimePoint until) {
  Slot& slot = ports_.at(index);
  slot.now = now;
  slot.until = until;
  RunIfAllGranted();
}

void VirtualTimeClient::RunIfAllGranted() {
  if (running_) return;
  std::optional<TimePoint> now, until;
  bool any = false;
  for (const Slot& slot : ports_) {
    if (slot.port == nullptr) continue;
    if (!slot.until) return;  // a connected port has no grant yet: wait for it
    any = true;
    if (until && *until != *slot.until && !mismatch_logged_) {
      mismatch_logged_ = true;
      spdlog::error(
          "virtual time: the ports of {} were granted different times; the buses of a node in virtual "
          "time must be served by one broker (it runs to the earliest)",
          clock_id_);
    }
    now = now ? std::max(*now, *slot.now) : *slot.now;
    until = until ? std::min(*until, *slot.until) : *slot.until;
  }
  if (!any) return;
  ++rounds_;
  running_ = true;
  struct Done {
    bool& flag;
    ~Done() { flag = false; }
  } done{running_};
  scheduler_.AdvanceTo(*now);
  for (Slot& slot : ports_)
    if (slot.port != nullptr) slot.port->ApplyHeld();
  scheduler_.AdvanceTo(*until);
  const std::optional<TimePoint> next = scheduler_.NextDeadline();
  for (Slot& slot : ports_) {
    if (slot.port == nullptr) continue;
    slot.now.reset();
    slot.until.reset();
    slot.port->Reached(*until, next);
  }
}

}  // namespace canfleet
