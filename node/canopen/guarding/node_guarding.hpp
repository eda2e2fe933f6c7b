#pragma once
/// @file Node guarding and life guarding, slave side (CiA 301 v4.2 §7.2.8.3.2.1; objects 100Ch
/// guard time and 100Dh life time factor, §7.5.2.11/§7.5.2.12).
///
/// Guard request (master → slave): remote frame, COB-ID 700h + node-ID.
/// Guard reply (slave → master), COB-ID 700h + node-ID, DLC 1:
///   bit 7: toggle t, 0 in the first reply after reset communication, then alternating
///   bits 6-0: NMT state, 04h stopped, 05h operational, 7Fh pre-operational

#include <cstdint>
#include <functional>
#include <vector>

#include "bus/bus_port.hpp"
#include "clock/scheduler.hpp"
#include "node/canopen/common/comm_error.hpp"
#include "node/canopen/common/nmt_state.hpp"
#include "node/canopen/od/object_dictionary.hpp"

namespace canfleet::canopen {

inline constexpr std::uint16_t kGuardTimeIndex = 0x100C;
inline constexpr std::uint16_t kLifeTimeFactorIndex = 0x100D;

/// Answers the master's guard requests and watches that they keep coming (life guarding).
///
/// - Every remote frame on 700h + node-ID is answered, whatever DLC the request carries
///   (python-canopen sends DLC 0, most masters DLC 1), in every state after boot-up.
/// - Life guarding (node life time = guard time × life time factor) starts at the first guard
///   request. No request within the life time: {kLifeGuardTimeout, own node-ID} active, once;
///   the next request clears it. It is off when 100Ch or 100Dh is 0 (CiA 301 §7.5.2.11/12), when
///   the objects are missing, and while 1017h ≠ 0: a device uses heartbeat or life guarding, not
///   both, and heartbeat wins (CiA 301 §7.2.8.3.2; Lely's nmt.c does the same). Guard requests
///   are still answered then: a master that guards gets its replies, and the reply costs nothing.
/// - A write of 100Ch, 100Dh or 1017h applies at once: a running life timer restarts with the new
///   life time from now; if life guarding is switched off a pending timeout is cleared.
class NodeGuarding {
 public:
  /// @param state the node's NMT state, read for each reply. Installs listeners on 100Ch, 100Dh
  ///        and 1017h; `od`, `port`, `scheduler` and `errors` must outlive it.
  NodeGuarding(ObjectDictionary& od, BusPort& port, Scheduler& scheduler, CommErrorSink& errors,
               std::function<NmtState()> state);

  /// Handles a guard request (remote frame on 700h + own node-ID): returns true and replies.
  /// Not answered while the node is Initialising or has no valid node-ID. Does not allocate.
  bool OnFrame(const CanFrame& frame);
  /// The 11-bit identifiers it listens to: the guarding RTR 700h + node-ID.
  void AddListenedIds(std::vector<std::uint32_t>& ids) const;

  /// The node-ID whose COB-ID the guard requests use (initially 0: none answered).
  void SetNodeId(std::uint8_t node_id) { node_id_ = node_id; }

  /// Reset communication: toggle back to 0, life guarding waits for the first request again, a
  /// pending life guard timeout is cleared.
  void Reset();

  /// True once a guard request started life guarding and it has not been reset or switched off.
  bool LifeGuarding() const { return guarding_started_; }
  /// The node life time (guard time × life time factor); zero when life guarding is off.
  Duration LifeTime() const;

 private:
  void OnConfigChanged();
  void OnLifeTimeExpired();
  void StopLifeGuarding();
  void ClearTimeout();

  ObjectDictionary& od_;
  BusPort& port_;
  CommErrorSink& errors_;
  std::function<NmtState()> state_;
  Timer life_timer_;
  std::uint8_t node_id_ = 0;
  bool toggle_ = false;
  bool guarding_started_ = false;
  bool timed_out_ = false;
  std::uint8_t reported_node_id_ = 0;
};

/// Adds 100Ch guard time (U16 ms, rw, default 0) and 100Dh life time factor (U8, rw, default 0).
void AddGuardingObjects(ObjectDictionary& od);

}  // namespace canfleet::canopen
