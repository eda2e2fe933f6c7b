#include "orchestrator/fleet/node_tracker.hpp"

#include <algorithm>

#include "vocabulary/nmt_state.hpp"

namespace canfleet::fleet {

const char* NmtStateName(std::optional<std::uint8_t> state) {
  return state ? canopen::ToString(static_cast<canopen::NmtState>(*state)) : "unknown";
}

void NodeTracker::Observe(const std::string& bus, const CanFrame& frame, TimePoint now) {
  if (frame.extended() || frame.remote() || frame.error()) return;
  const std::uint32_t id = frame.id;
  if (id > 0x700 && id <= 0x77F && frame.dlc == 1) {
    // CiA 301 §7.2.8.3.2: the state byte's bit 7 is the toggle bit of node guarding replies;
    // heartbeats and boot-up have it clear.
    const auto node_id = static_cast<std::uint8_t>(id - 0x700);
    const auto state = static_cast<std::uint8_t>(frame.data[0] & 0x7F);
    auto& live = nodes_[{bus, node_id}];
    if (state == 0x00) {  // a boot-up starts over
      live.heartbeat_period.reset();
      live.last_interval.reset();
    } else if (live.last_heartbeat && now > *live.last_heartbeat) {
      const Duration interval = now - *live.last_heartbeat;
      live.heartbeat_period = live.last_interval ? std::min(interval, *live.last_interval) : interval;
      live.last_interval = interval;
    }
    live.nmt_state = state;
    live.last_heartbeat = now;
    if (state == 0x00) {
      live.booted = true;
      if (on_boot_up_) on_boot_up_(bus, node_id);
    }
    return;
  }
  if (id > 0x080 && id <= 0x0FF && frame.dlc == 8) {
    const auto node_id = static_cast<std::uint8_t>(id - 0x080);
    const auto& d = frame.data;
    SeenEmcy emcy;
    emcy.code = static_cast<std::uint16_t>(d[0] | (d[1] << 8));
    emcy.error_register = d[2];
    for (std::size_t i = 0; i < emcy.manufacturer.size(); ++i)
      emcy.manufacturer[i] = d[3 + i];
    emcy.time = now;
    auto& live = nodes_[{bus, node_id}];
    live.last_emcy = emcy;
    ++live.emcy_count;
    if (on_emcy_) on_emcy_(bus, node_id, emcy);
  }
}

const NodeLiveState* NodeTracker::Find(const std::string& bus, std::uint8_t node_id) const {
  auto it = nodes_.find({bus, node_id});
  return it == nodes_.end() ? nullptr : &it->second;
}

void NodeTracker::Forget(const std::string& bus, std::uint8_t node_id) {
  nodes_.erase({bus, node_id});
}

}  // namespace canfleet::fleet
