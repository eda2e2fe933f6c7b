#pragma once
/// @file SYNC consumer and producer (CiA 301 v4.2 §7.2.5; objects 1005h, 1006h, 1007h, 1019h).
///
/// SYNC frame, COB-ID from 1005h (default 080h):
///   1019h = 0:      DLC 0, no data
///   1019h = 2..240: DLC 1, byte 0 = counter, 1..1019h then back to 1

#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "bus/bus_port.hpp"
#include "bus/can_frame.hpp"
#include "clock/scheduler.hpp"
#include "node/canopen/common/comm_error.hpp"
#include "node/canopen/common/nmt_state.hpp"
#include "node/canopen/od/object_dictionary.hpp"
#include "node/canopen/sync/sync_objects.hpp"

namespace canfleet::canopen {

/// Consumes SYNC (and produces it when 1005h bit 30 is set) and tells its listeners, e.g. the PDO
/// service, about every SYNC.
///
/// - Runs in pre-operational and operational only (CiA 301 §7.3.2.2, table 51).
/// - Consumer: a SYNC whose DLC is not the one 1019h implies is not a SYNC event: it is ignored and
///   {kSyncLength} is reported active, once; the next well-formed SYNC clears it (the error policy
///   turns it into EMCY 8240h). While this node is the producer, SYNC frames from others on its
///   COB-ID are ignored (two producers is a configuration error, not a second time base).
/// - Producer (1005h bit 30 and 1006h ≠ 0): the first SYNC is due one period after production
///   starts (entering pre-operational/operational, or a write that enables it), each next one a
///   period after the previous deadline, so the period does not drift. The counter restarts at 1
///   whenever production starts or 1019h changes. A write of 1006h while producing re-arms the
///   next SYNC one new period after the write. The producer dispatches its own SYNC to the
///   listeners (a CAN controller does not receive its own frames).
/// - Without 1005h the node consumes SYNC on 080h (the pre-defined connection set). Without 1006h
///   it never produces; without 1007h there is no window; without 1019h there is no counter.
/// - Not done: the consumer timeout (no SYNC within 1.5 × 1006h, CANopenNode EMCY 8100h): there
///   is no CommErrorKind for it.
class SyncService {
 public:
  /// Installs validators and listeners on 1005h/1006h/1019h; `od`, `port`, `scheduler` and
  /// `errors` must outlive the service.
  SyncService(ObjectDictionary& od, BusPort& port, Scheduler& scheduler, CommErrorSink& errors);
  SyncService(const SyncService&) = delete;
  SyncService& operator=(const SyncService&) = delete;

  /// SYNC is consumed and produced in pre-operational and operational only.
  void SetNmtState(NmtState state);

  /// Handles a SYNC frame: true if the frame has the SYNC COB-ID (format included) and the NMT
  /// state lets the service act on it, even if it was rejected for its length. Does not allocate.
  bool OnFrame(const CanFrame& frame);
  /// The 11-bit identifiers it listens to: the SYNC COB-ID (1005h), also as producer (another
  /// producer on the bus is an error it must see).
  void AddListenedIds(std::vector<std::uint32_t>& ids) const {
    if (!cob_.extended) ids.push_back(cob_.can_id);
  }

  /// Adds a listener called at every SYNC, received or produced, with the counter (0 when
  /// 1019h = 0). Listeners run in the order they were added.
  void OnSync(std::function<void(std::uint8_t counter)> listener);

  /// True within 1007h µs (inclusive) after the last SYNC; always true when 1007h is 0 or absent;
  /// false before the first SYNC when a window is set.
  bool InsideWindow() const;

  /// True while this node sends SYNC.
  bool Producing() const { return producer_timer_.Armed(); }
  /// The time of the last SYNC received or produced, if any.
  std::optional<TimePoint> LastSync() const { return last_sync_; }

 private:
  void Configure();
  void Produce();
  void Dispatch(std::uint8_t counter);
  std::uint32_t PeriodUs() const;
  std::uint8_t Overflow() const;

  BusPort& port_;
  Scheduler& scheduler_;
  CommErrorSink& errors_;
  SubObject* cob_id_;    // 1005h, may be null
  SubObject* period_;    // 1006h, may be null
  SubObject* window_;    // 1007h, may be null
  SubObject* overflow_;  // 1019h, may be null

  SyncCobId cob_{};
  std::uint32_t active_period_us_ = 0;
  std::uint8_t active_overflow_ = 0;
  bool allowed_ = false;
  bool length_error_ = false;
  std::uint8_t next_counter_ = 1;
  std::optional<TimePoint> last_sync_;
  std::vector<std::function<void(std::uint8_t)>> listeners_;
  Timer producer_timer_;
};

}  // namespace canfleet::canopen
