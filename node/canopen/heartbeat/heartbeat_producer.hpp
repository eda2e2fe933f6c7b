#pragma once
/// @file Heartbeat producer (CiA 301 v4.2 §7.2.8.3.2.2; object 1017h, §7.5.2.20).
///
/// Heartbeat (producer → consumers), COB-ID 700h + node-ID, DLC 1:
///   byte 0: NMT state, 04h stopped, 05h operational, 7Fh pre-operational (§7.2.8.3.2.2)

#include <cstdint>
#include <functional>

#include "bus/bus_port.hpp"
#include "clock/scheduler.hpp"
#include "node/canopen/common/nmt_state.hpp"
#include "node/canopen/heartbeat/heartbeat_objects.hpp"
#include "node/canopen/od/object_dictionary.hpp"

namespace canfleet::canopen {

/// Sends the node's heartbeat every 1017h ms once started. Without 1017h it never sends.
///
/// Timing: Start() arms the first heartbeat one period later (the boot-up frame counts as the
/// first heartbeat, CiA 301 §7.2.8.3.2.2); each following one is due exactly one period after the
/// previous deadline, so the period does not drift. A write of 1017h takes effect at once: the
/// next heartbeat is due one new period after the write (0 stops production).
class HeartbeatProducer {
 public:
  /// @param state the node's NMT state, read at each heartbeat. The producer installs a listener
  ///        on 1017h; `od`, `port` and `scheduler` must outlive it.
  HeartbeatProducer(ObjectDictionary& od, BusPort& port, Scheduler& scheduler,
                    std::function<NmtState()> state);

  /// The node-ID whose COB-ID (700h + id) the heartbeat uses. No heartbeat is sent while the
  /// node-ID is not 1..127 (the initial value is 0).
  void SetNodeId(std::uint8_t node_id);

  /// Starts production (call after boot-up).
  void Start();
  /// Stops production (reset, or before boot-up).
  void Stop();

  bool Running() const { return running_; }
  /// The current producer time from 1017h (0 = off).
  Duration Period() const;

 private:
  void Arm();
  void OnTimer();

  ObjectDictionary& od_;
  BusPort& port_;
  std::function<NmtState()> state_;
  Timer timer_;
  std::uint8_t node_id_ = 0;
  bool running_ = false;
};

}  // namespace canfleet::canopen
