#pragma once
/// @file CANopen-Diag-like statistics per node from the frames on a bus (ESAcademy's CANopen Diag
/// shows these): the heartbeat period's minimum, maximum and jitter (the standard deviation of the
/// periods), boot-ups, SDO response times (a server's answer 580h+ID after a client's request
/// 600h+ID, CiA 301 §7.2.4), EMCYs. Pure: frames come with their bus time (simulated in virtual
/// time), so unit tests drive it by hand.

#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "bus/can_frame.hpp"

namespace canfleet::web {

struct NodeDiag {
  std::uint64_t heartbeats = 0;  ///< heartbeat frames (state byte not 00h)
  std::uint64_t bootups = 0;     ///< boot-up frames (700h+ID, 00h)
  std::optional<std::int64_t> hb_min_ns, hb_max_ns;
  double hb_mean_ns = 0, hb_m2 = 0;  ///< Welford's running mean and sum of squares of the periods
  std::uint64_t periods = 0;
  std::optional<std::int64_t> last_heartbeat_ns;
  std::uint64_t sdo_responses = 0;
  std::uint64_t sdo_aborts = 0;
  std::optional<std::int64_t> sdo_min_ns, sdo_max_ns, sdo_last_ns;
  std::optional<std::int64_t> sdo_pending_since_ns;  ///< a request waiting for its answer
  std::uint64_t emcys = 0;

  /// The heartbeat period's standard deviation in ns (0 with fewer than two periods).
  double JitterNs() const;
};

class DiagStats {
 public:
  /// A frame that ended at `time_ns` on `bus`.
  void Frame(const std::string& bus, const CanFrame& frame, std::int64_t time_ns);
  /// The node at (bus, node-ID); nullptr when no frame of it was seen.
  const NodeDiag* Find(const std::string& bus, std::uint8_t node_id) const;
  /// {"hb_min_ms", "hb_max_ms", "hb_jitter_ms", "heartbeats", "bootups", "sdo_min_ms", "sdo_max_ms",
  /// "sdo_last_ms", "sdo_responses", "sdo_aborts", "emcys"}; absent figures are null.
  static std::string Json(const NodeDiag& diag);

 private:
  std::map<std::pair<std::string, std::uint8_t>, NodeDiag> nodes_;
};

}  // namespace canfleet::web
