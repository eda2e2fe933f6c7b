#pragma once
/// @file What the master sees of each node on the wire: boot-up and heartbeat (700h + id), EMCY
/// (80h + id). The fleet joins this to its node names for `canfleet status`; a real CiA 302 master
/// keeps the same table (its NMT slave assignment and error control).

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <utility>

#include "bus/can_frame.hpp"
#include "clock/scheduler.hpp"

namespace canfleet::fleet {

struct SeenEmcy {
  std::uint16_t code = 0;
  std::uint8_t error_register = 0;
  std::array<std::uint8_t, 5> manufacturer{};
  TimePoint time{};
};

struct NodeLiveState {
  bool booted = false;                      ///< a boot-up frame was seen since Forget()
  std::optional<std::uint8_t> nmt_state;    ///< last heartbeat/boot-up state byte (00h, 04h, 05h, 7Fh)
  std::optional<TimePoint> last_heartbeat;  ///< or boot-up
  /// The producer time as seen on the wire: the shorter of the last two intervals between
  /// heartbeats (a gap, which is what staleness is about, does not stretch it; a producer time
  /// changed for good is taken after two heartbeats).
  std::optional<Duration> heartbeat_period;
  std::optional<Duration> last_interval;
  std::optional<SeenEmcy> last_emcy;
  std::uint64_t emcy_count = 0;

  /// The NMT state is old news: a node that has been sending heartbeats has sent none for three
  /// of its periods (a flood, a partition, a hung process). `canfleet status` says so rather than
  /// show a state it has not seen recently. A node without periodic heartbeats is never stale.
  bool Stale(TimePoint now) const {
    return heartbeat_period && last_heartbeat && now - *last_heartbeat > 3 * *heartbeat_period;
  }
};

/// "pre-operational", "operational", "stopped", "initialising" (boot-up), "unknown".
const char* NmtStateName(std::optional<std::uint8_t> state);

class NodeTracker {
 public:
  using BootUpHandler = std::function<void(const std::string& bus, std::uint8_t node_id)>;
  using EmcyHandler = std::function<void(const std::string& bus, std::uint8_t node_id, const SeenEmcy&)>;

  void OnBootUp(BootUpHandler handler) { on_boot_up_ = std::move(handler); }
  void OnEmcy(EmcyHandler handler) { on_emcy_ = std::move(handler); }

  /// Looks at one frame seen on `bus` at scheduler time `now`.
  void Observe(const std::string& bus, const CanFrame& frame, TimePoint now);

  /// Null when nothing was ever seen from that node.
  const NodeLiveState* Find(const std::string& bus, std::uint8_t node_id) const;

  /// The node's process is gone or restarting: what was seen is history.
  void Forget(const std::string& bus, std::uint8_t node_id);

 private:
  std::map<std::pair<std::string, std::uint8_t>, NodeLiveState> nodes_;
  BootUpHandler on_boot_up_;
  EmcyHandler on_emcy_;
};

}  // namespace canfleet::fleet
