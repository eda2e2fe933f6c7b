#pragma once
/// @file Heartbeat consumer (CiA 301 v4.2 §7.2.8.3.2.2; object 1016h, §7.5.2.19).
///
/// 1016h sub1..n, UNSIGNED32 (§7.5.2.19):
///   bits 31-24: reserved (00h)   bits 23-16: node-ID of the producer   bits 15-0: consumer time, ms
/// An entry is active only if its node-ID is 1..127 and its time is not 0.
/// Heartbeat received, COB-ID 700h + producer node-ID, DLC 1:
///   byte 0: producer state, 00h boot-up, 04h stopped, 05h operational, 7Fh pre-operational

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "bus/can_frame.hpp"
#include "clock/scheduler.hpp"
#include "node/canopen/common/comm_error.hpp"
#include "node/canopen/common/nmt_state.hpp"
#include "node/canopen/heartbeat/heartbeat_objects.hpp"
#include "node/canopen/od/object_dictionary.hpp"

namespace canfleet::canopen {

/// What the consumer knows about one 1016h entry.
struct HeartbeatConsumerStatus {
  std::uint8_t node_id;  ///< bits 23-16 of the entry, as configured
  Duration period;       ///< bits 15-0 of the entry (consumer time)
  enum class State {
    kUnconfigured,  ///< node-ID not 1..127, time 0, or node-ID already monitored by an earlier entry
    kWaiting,       ///< configured; no heartbeat received yet (or since the producer's boot-up)
    kActive,        ///< heartbeats arrive within the consumer time
    kTimedOut,      ///< the last heartbeat is older than the consumer time
  } state;
  NmtState last_state;       ///< state byte of the last heartbeat/boot-up (kInitialising if none)
  std::uint8_t sub_index{};  ///< the 1016h sub-index of the entry
};

/// Monitors the heartbeats of the nodes listed in 1016h and reports their loss to `errors`.
///
/// - Monitoring of an entry starts at the first heartbeat received; a boot-up does not start it
///   (CiA 301 §7.2.8.3.2.2; the device manuals say "monitoring starts at the first heartbeat").
/// - No heartbeat within the consumer time after the previous one: {kHeartbeatTimeout, node}
///   active, once; the next heartbeat clears it (inactive) and monitoring goes on.
/// - A boot-up from a node whose monitoring had started (active or timed out): the node was
///   reset. A pending timeout is cleared, {kBootUpOfMonitored, node} is reported (active, then
///   inactive: it is an event) and the entry waits for the first heartbeat again.
/// - Writing an entry restarts its monitoring (waiting); Reset() restarts every entry. An entry
///   that stops being monitored while timed out reports its timeout cleared, so no error stays
///   active for a node nobody watches any more.
/// - SDO writes: an active node-ID already used by another active entry → kParameterIncompatible
///   (06040043h); sub0 → kReadOnly (06010002h).
/// Without 1016h the consumer does nothing.
class HeartbeatConsumer {
 public:
  /// Installs validators and listeners on 1016h; `od`, `scheduler` and `errors` must outlive it.
  HeartbeatConsumer(ObjectDictionary& od, Scheduler& scheduler, CommErrorSink& errors);
  ~HeartbeatConsumer();
  HeartbeatConsumer(const HeartbeatConsumer&) = delete;
  HeartbeatConsumer& operator=(const HeartbeatConsumer&) = delete;

  /// Looks at 700h+x data frames with DLC 1 from monitored nodes (other DLCs are ignored, as in
  /// CANopenNode's CO_HBconsumer). Always returns false: the frame is not consumed, so other
  /// services (e.g. an NMT master view) still see it. Does not allocate.
  bool OnFrame(const CanFrame& frame);
  /// The 11-bit identifiers it listens to: the heartbeats of the nodes it monitors (1016h).
  void AddListenedIds(std::vector<std::uint32_t>& ids) const;
  /// The heartbeats whose arrival makes the node send nothing at once (virtual time, per-node
  /// lookahead): each watched producer that has not timed out, with its consumer time, before
  /// which nothing follows from it.
  void AddPassiveIds(std::vector<std::pair<std::uint32_t, Duration>>& out) const;

  /// Restarts monitoring (reset communication): every configured entry goes back to waiting.
  void Reset();

  /// One status per 1016h entry, in sub-index order.
  std::vector<HeartbeatConsumerStatus> Status() const;

 private:
  struct Entry;

  void Apply(std::uint8_t restart_sub, bool restart_all);
  void Receive(Entry& entry, std::uint8_t state_byte);
  void OnTimeout(Entry& entry);
  void StopMonitoring(Entry& entry);
  SdoAbort Validate(std::uint8_t sub_index, std::span<const std::uint8_t> data) const;

  ObjectDictionary& od_;
  CommErrorSink& errors_;
  std::vector<std::unique_ptr<Entry>> entries_;  // fixed after construction
};

}  // namespace canfleet::canopen
