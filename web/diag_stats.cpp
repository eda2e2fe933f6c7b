#include "web/diag_stats.hpp"

#include <cmath>
#include <cstdio>

namespace canfleet::web {

double NodeDiag::JitterNs() const {
  return periods < 2 ? 0.0 : std::sqrt(hb_m2 / static_cast<double>(periods - 1));
}

void DiagStats::Frame(const std::string& bus, const CanFrame& frame, std::int64_t time_ns) {
  if (frame.extended() || frame.error() || frame.remote()) return;
  const auto node_id = static_cast<std::uint8_t>(frame.id & 0x7F);
  if (node_id == 0) return;
  if ((frame.id & 0x780) == 0x700 && frame.dlc >= 1) {  // heartbeat or boot-up (CiA 301 §7.2.8.3.2)
    NodeDiag& d = nodes_[{bus, node_id}];
    if (frame.data[0] == 0x00) {
      ++d.bootups;
      d.last_heartbeat_ns.reset();  // a new life: its first period starts at its next heartbeat
      return;
    }
    ++d.heartbeats;
    if (d.last_heartbeat_ns) {
      const std::int64_t period = time_ns - *d.last_heartbeat_ns;
      d.hb_min_ns = d.hb_min_ns ? std::min(*d.hb_min_ns, period) : period;
      d.hb_max_ns = d.hb_max_ns ? std::max(*d.hb_max_ns, period) : period;
      ++d.periods;
      const double delta = static_cast<double>(period) - d.hb_mean_ns;
      d.hb_mean_ns += delta / static_cast<double>(d.periods);
      d.hb_m2 += delta * (static_cast<double>(period) - d.hb_mean_ns);
    }
    d.last_heartbeat_ns = time_ns;
  } else if (frame.id >= 0x601 && frame.id <= 0x67F) {  // SDO request to the node
    nodes_[{bus, node_id}].sdo_pending_since_ns = time_ns;
  } else if (frame.id >= 0x581 && frame.id <= 0x5FF) {  // SDO response from the node
    NodeDiag& d = nodes_[{bus, node_id}];
    if (!d.sdo_pending_since_ns) return;  // a response to a request made before we watched
    const std::int64_t dt = time_ns - *d.sdo_pending_since_ns;
    d.sdo_pending_since_ns.reset();
    ++d.sdo_responses;
    if (frame.dlc >= 1 && frame.data[0] == 0x80) ++d.sdo_aborts;
    d.sdo_min_ns = d.sdo_min_ns ? std::min(*d.sdo_min_ns, dt) : dt;
    d.sdo_max_ns = d.sdo_max_ns ? std::max(*d.sdo_max_ns, dt) : dt;
    d.sdo_last_ns = dt;
  } else if (frame.id >= 0x081 && frame.id <= 0x0FF) {  // EMCY (CiA 301 §7.2.7)
    ++nodes_[{bus, node_id}].emcys;
  }
}

const NodeDiag* DiagStats::Find(const std::string& bus, std::uint8_t node_id) const {
  const auto it = nodes_.find({bus, node_id});
  return it == nodes_.end() ? nullptr : &it->second;
}

namespace {

std::string Ms(const std::optional<std::int64_t>& ns) {
  if (!ns) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", static_cast<double>(*ns) / 1e6);
  return buf;
}

}  // namespace

std::string DiagStats::Json(const NodeDiag& d) {
  char jitter[32];
  std::snprintf(jitter, sizeof jitter, "%.3f", d.JitterNs() / 1e6);
  return "{\"hb_min_ms\":" + Ms(d.hb_min_ns) + ",\"hb_max_ms\":" + Ms(d.hb_max_ns) +
         ",\"hb_jitter_ms\":" + (d.periods >= 2 ? std::string(jitter) : "null") +
         ",\"heartbeats\":" + std::to_string(d.heartbeats) + ",\"bootups\":" + std::to_string(d.bootups) +
         ",\"sdo_min_ms\":" + Ms(d.sdo_min_ns) + ",\"sdo_max_ms\":" + Ms(d.sdo_max_ns) +
         ",\"sdo_last_ms\":" + Ms(d.sdo_last_ns) + ",\"sdo_responses\":" + std::to_string(d.sdo_responses) +
         ",\"sdo_aborts\":" + std::to_string(d.sdo_aborts) + ",\"emcys\":" + std::to_string(d.emcys) + "}";
}

}  // namespace canfleet::web
