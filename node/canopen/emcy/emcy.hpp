#pragma once
/// @file The EMCY producer and the error bookkeeping behind it (CiA 301 v4.2 §7.2.7): active errors,
/// the error register 1001h (§7.5.2.2), the pre-defined error field 1003h (§7.5.2.4), the EMCY
/// COB-ID 1014h (§7.5.2.17) and the EMCY inhibit time 1015h (§7.5.2.18).
///
/// EMCY write (CiA 301 §7.2.7.3.1), COB-ID from 1014h (default 80h + node-ID), DLC 8:
///   bytes 0-1  emergency error code, little-endian (0000h = error reset / no error)
///   byte  2    error register (1001h) after the event
///   bytes 3-7  manufacturer-specific error field (ErrorEntry::msef; zero in an error reset)
///
/// 1003h entry, UNSIGNED32 (CiA 301 §7.5.2.4), newest at sub-index 1, sub-index 0 = count:
///   bits 31-16 manufacturer-specific additional information (ErrorEntry::info)
///   bits 15-0  emergency error code (ErrorEntry::code)

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include "bus/bus_port.hpp"
#include "bus/can_frame.hpp"
#include "clock/scheduler.hpp"
#include "node/canopen/common/nmt_state.hpp"
#include "node/canopen/emcy/cob_id.hpp"
#include "node/canopen/emcy/error_entry.hpp"
#include "node/canopen/od/object_dictionary.hpp"

namespace canfleet::canopen {

struct EmcyOptions {
  /// Most entries kept in 1003h; 0 = as many as 1003h declares. Never more than 1003h declares
  /// (e.g. the power supply declares 15 sub-indexes and keeps 4).
  std::size_t max_history = 0;
  /// The five device manuals remove an entry from 1003h when its error clears. false keeps
  /// cleared entries until newer ones push them out.
  bool remove_cleared_from_history = true;
  /// When one error clears while others stay active, send an error-reset EMCY (0000h with the
  /// remaining 1001h). CiA 301 §7.2.7.1 (error state diagram, transition 3) allows it; CANopenNode
  /// sends one for every cleared error. false sends the error reset only when the last one clears.
  bool reset_emcy_on_partial_clear = true;
};

/// The EMCY producer of one node.
///
/// Raise/Clear update 1001h and 1003h at once, in every NMT state. Frames go out only when
///  - the NMT state is Pre-operational or Operational (CiA 301 §7.3.2.2, table 51),
///  - 1014h is valid (bit 31 = 0), and, for the default COB-ID, the node-ID is 1..127,
/// and at most one per 1015h inhibit time. A frame raised during the inhibit time waits in a
/// queue of kQueueCapacity frames and goes out when the inhibit time has passed (a Timer). When the
/// queue is full the oldest waiting frame is dropped so that the receiver sees the latest state;
/// Overruns() counts the drops. A frame that may not go out when it is raised (Stopped, 1014h
/// invalid) is not sent later either: an EMCY reports an event as it happens, and 1001h/1003h keep
/// the state. Leaving Pre-operational/Operational or invalidating 1014h drops the waiting frames.
/// The error register byte of a waiting frame is the one at the time of the event.
///
/// The service owns the values of 1001h, 1003h and 1014h: it keeps them current (a read of 1003h
/// past the count answers kNoData through a read hook) and restores them when something else
/// overwrites them (e.g.
/// ObjectDictionary::RestoreDefaults at reset communication, which therefore keeps the history and
/// the active errors: ClearAll() is the reset-node path). Missing objects are tolerated: without
/// 1001h the register is only kept internally, without 1003h there is no history, without 1014h
/// the COB-ID is 80h + node-ID, without 1015h there is no inhibit time.
///
/// Steady state does not allocate: the history and active lists are reserved up front, waiting
/// frames sit in a fixed ring, and the OD values are rewritten in place.
class Emcy {
 public:
  /// Frames that can wait for the inhibit time to pass.
  static constexpr std::size_t kQueueCapacity = 16;

  /// Installs the hooks on 1001h, 1003h, 1014h and 1015h (whichever exist) and reads their values.
  /// All references must outlive the service; the OD's objects must not be replaced meanwhile.
  Emcy(ObjectDictionary& od, BusPort& port, Scheduler& scheduler, EmcyOptions options = {});
  Emcy(const Emcy&) = delete;
  Emcy& operator=(const Emcy&) = delete;

  /// The node-ID used by the default COB-ID (80h + node-ID). A 1014h CAN-ID of 080h or of 80h + the
  /// node-ID stands for "the default", as in CANopenNode, so it follows later node-ID changes.
  /// Outside 1..127 (e.g. FFh, unconfigured) the default COB-ID sends nothing.
  void SetNodeId(std::uint8_t node_id);

  /// Gates frames by NMT state (CiA 301 §7.3.2.2 table 51); errors are recorded in every state.
  /// The service starts in Initialising, so nothing is sent before the stack reports the state.
  void SetNmtState(NmtState state);

  /// Records `error` as active: 1001h gets bit 0 and its register bits, 1003h gets its entry at
  /// sub-index 1 (older entries move down, the oldest falls off beyond the history size), and an
  /// EMCY with its code goes out. Nothing happens when the same (code, info) is already active, or
  /// for code 0000h, which means "error reset".
  void Raise(const ErrorEntry& error);

  /// Ends the active error (code, info): its 1003h entry is removed (remove_cleared_from_history),
  /// 1001h is recomputed, and an error-reset EMCY goes out (CiA 301 §7.2.7.1): code 0000h, the new
  /// 1001h, manufacturer bytes zero. With other errors still active it is sent only when
  /// reset_emcy_on_partial_clear. Nothing happens when (code, info) is not active. Bus-off is no
  /// exception: its 8140h entry leaves 1003h at the error reset sent after the recovery (the five
  /// manuals' 1003h: "immediately removed when the error condition has been cleared").
  void Clear(std::uint16_t code, std::uint16_t info);

  /// Forgets every active error and the history, drops waiting frames and the inhibit state, and
  /// sets 1001h to 0, without sending anything: the reset-node path (the node boots again).
  void ClearAll();

  /// Empties 1003h as an SDO write of 0 to 1003h sub-index 0 does. Active errors stay active and
  /// 1001h is unchanged (the five manuals: "clearing 1003h does not end the error state").
  void ClearHistory();

  bool IsActive(std::uint16_t code, std::uint16_t info) const;
  std::size_t ActiveCount() const { return active_.size(); }
  /// Active errors, oldest first.
  std::span<const ErrorEntry> ActiveErrors() const { return active_; }
  /// 1003h entries, newest first.
  std::span<const std::uint32_t> History() const { return history_; }
  /// The 1001h value: 0 without active errors, else bit 0 | the register bits of every active error.
  std::uint8_t ErrorRegister() const { return error_register_; }

  /// The last EMCY frame the port accepted.
  std::optional<CanFrame> LastSent() const { return last_sent_; }
  /// Called with every EMCY frame the port accepted (telemetry). One listener; a new one replaces it.
  void OnSent(std::function<void(const CanFrame&)> listener) { on_sent_ = std::move(listener); }
  /// Frames dropped because the inhibit queue was full.
  std::size_t Overruns() const { return overruns_; }

  /// Adds a listener called whenever the set of active errors changes (Raise, Clear, ClearAll),
  /// after 1001h and 1003h were updated: device logic that follows the fault state (the Quad's
  /// outputs, AX020506 §4.2) wakes with it instead of polling ActiveCount().
  void AddActiveListener(std::function<void()> listener) { active_listeners_.push_back(std::move(listener)); }

  /// The controller is back from bus-off: frames the port refused while bus-off (above all the
  /// 8140h "recovered from bus-off" EMCY raised at bus-off) go out now, in order, inhibit time
  /// permitting — as CANopenNode's EMCY FIFO sends them once the controller transmits again.
  void OnBusOffEnded();

 private:
  /// A 1014h CAN-ID (11-bit) that stands for "80h + node-ID".
  bool FollowsNodeId(std::uint32_t can_id) const;
  /// The value 1014h reads: the stored COB-ID with the node-ID applied to the default.
  std::uint32_t CobIdValue() const;
  bool MaySend() const;

  void Emit(std::uint16_t code, const std::array<std::uint8_t, 5>& msef);
  void Transmit(CanFrame frame);
  void OnInhibitExpired();
  void DropQueue();

  void LoadCobId(std::uint32_t value);
  void LoadInhibitTime();
  void InstallHooks();

  void NotifyActiveChanged();
  void PushHistory(std::uint32_t value);
  void RemoveFromHistory(std::uint32_t value);
  void RecomputeRegister();
  /// Writes `value` into `sub` (as the device, so other listeners run) unless it is there already.
  void Store(SubObject& sub, std::uint64_t value);
  /// Copy the internal state into 1001h, 1003h and 1014h.
  void SyncRegister();
  void SyncHistory();
  void SyncCobId();

  ObjectDictionary& od_;
  BusPort& port_;
  Scheduler& scheduler_;
  EmcyOptions options_;

  SubObject* register_sub_ = nullptr;   // 1001h
  SubObject* count_sub_ = nullptr;      // 1003h sub-index 0
  std::vector<SubObject*> entry_subs_;  // 1003h sub-indexes 1..n
  SubObject* cob_id_sub_ = nullptr;     // 1014h
  std::size_t history_capacity_ = 0;

  std::vector<ErrorEntry> active_;
  std::vector<std::uint32_t> history_;  // newest first
  std::uint8_t error_register_ = 0;

  std::uint8_t node_id_ = 0;
  NmtState nmt_state_ = NmtState::kInitialising;
  EmcyCobId cob_id_{.valid = true, .extended = false, .can_id = kEmcyFunctionCode};  // as stored

  Duration inhibit_time_{0};
  std::optional<TimePoint> last_transmit_;
  std::array<CanFrame, kQueueCapacity> queue_{};  // ring of frames waiting for the inhibit time
  std::size_t queue_head_ = 0;
  std::size_t queue_size_ = 0;
  std::size_t overruns_ = 0;
  bool held_by_bus_off_ = false;  // the queue's head was refused by a bus-off controller

  std::optional<CanFrame> last_sent_;
  std::function<void(const CanFrame&)> on_sent_;
  std::vector<std::function<void()>> active_listeners_;
  bool syncing_ = false;  // set while the service writes its own objects: its listeners ignore that
  Timer inhibit_timer_;
};

/// Creates the CiA 301 EMCY objects with their standard defaults:
///   1001h error register, UNSIGNED8 ro, 0 (TPDO-mappable);
///   1003h pre-defined error field, ARRAY: sub 0 UNSIGNED8 rw 0, sub 1..history_entries UNSIGNED32
///         ro 0 (no 1003h when history_entries is 0);
///   1014h COB-ID EMCY, UNSIGNED32 rw, $NODEID+80h;
///   1015h inhibit time EMCY, UNSIGNED16 rw, 0 (100 µs units).
void AddEmcyObjects(ObjectDictionary& od, std::uint8_t history_entries);

}  // namespace canfleet::canopen
