#pragma once
/// @file The PDO service (CiA 301 v4.2 §7.2.2): every RPDO and TPDO the object dictionary declares
/// (1400h–15FFh and 1800h–19FFh, mapping records 200h above), their write rules, reception,
/// transmission and timers. See rpdo.hpp and tpdo.hpp for the behaviour of one PDO.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "bus/bus_port.hpp"
#include "bus/can_frame.hpp"
#include "clock/scheduler.hpp"
#include "node/canopen/common/comm_error.hpp"
#include "node/canopen/common/nmt_state.hpp"
#include "node/canopen/od/object_dictionary.hpp"
#include "node/canopen/pdo/pdo_context.hpp"
#include "node/canopen/pdo/pdo_objects.hpp"
#include "node/canopen/pdo/rpdo.hpp"
#include "node/canopen/pdo/tpdo.hpp"

namespace canfleet::canopen {

/// Runs the PDOs of one node.
///
/// - The PDOs are the communication records present when the service is built: RPDO n at
///   1400h + n − 1 (mapping 1600h + n − 1), TPDO n at 1800h + n − 1 (mapping 1A00h + n − 1). A
///   record without sub1 is not a PDO; a PDO without a mapping record maps nothing.
/// - The service installs validators (the write rules of PdoConfig) and listeners on every
///   sub-object of those records: a committed write, including RestoreDefaults, reconfigures that
///   PDO at once. Each mapping is resolved to SubObject pointers then, so the frame path does no
///   dictionary lookup and no allocation (receiving, SYNC, events, timers, transmission).
/// - PDOs run in operational only (CiA 301 §7.3.2.2, table 51).
/// - 1007h, if present, is the synchronous window for synchronous RPDOs.
class PdoService {
 public:
  /// `od`, `port`, `scheduler` and `errors` must outlive the service; the service must live as
  /// long as the OD (its hooks point to it).
  PdoService(ObjectDictionary& od, BusPort& port, Scheduler& scheduler, CommErrorSink& errors);
  PdoService(const PdoService&) = delete;
  PdoService& operator=(const PdoService&) = delete;
  ~PdoService();

  /// The COB-IDs are plain dictionary values (the stack applies $NODEID when it restores
  /// defaults), so this only re-reads every PDO's configuration and restarts it.
  void SetNodeId(std::uint8_t node_id);

  /// PDOs run in operational only: entering it starts the TPDO event timers (RPDO deadlines start
  /// with each RPDO's first frame); leaving it stops every timer and drops buffered SYNC data.
  void SetNmtState(NmtState state);

  /// A data frame on an RPDO COB-ID, or a remote frame on a TPDO COB-ID. True if a PDO in use took
  /// it. Does not allocate.
  bool OnFrame(const CanFrame& frame);
  /// The 11-bit identifiers it listens to: its active RPDOs, and its TPDOs (a remote request).
  void AddListenedIds(std::vector<std::uint32_t>& ids) const;

  /// Wire to SyncService::OnSync: applies buffered synchronous RPDOs, then sends the synchronous
  /// TPDOs due and samples type 252 TPDOs. `counter` is 0 when the SYNC has no counter.
  void OnSync(std::uint8_t counter);

  /// Device hook: `sub` changed. Every TPDO mapping it gets an event (254/255: sent, respecting
  /// its inhibit time; 0: sent at the next SYNC). No dictionary lookup.
  void NotifyChanged(const SubObject& sub);

  /// Device/application event for TPDO `tpdo_number` (1-based); ignored if there is none.
  void RequestTpdo(std::size_t tpdo_number);

  /// Device hook: asked before every TPDO transmission with its number (1-based) and mapping;
  /// returning false keeps the frame off the bus (e.g. a manual that sends no CAN message for a
  /// disabled channel). One gate; a new one replaces it.
  void SetTpdoGate(std::function<bool(std::size_t tpdo_number, std::span<const MappedObject> entries)> gate) {
    ctx_.tpdo_gate = std::move(gate);
  }

  const PdoCounters& Counters() const { return counters_; }
  /// Number of RPDOs/TPDOs found in the dictionary.
  std::size_t RpdoCount() const { return rpdos_.size(); }
  std::size_t TpdoCount() const { return tpdos_.size(); }

 private:
  template <typename Pdo>
  void InstallHooks(Pdo& pdo);

  PdoCounters counters_;
  PdoContext ctx_;
  bool operational_ = false;
  std::vector<std::unique_ptr<Rpdo>> rpdos_;
  std::vector<std::unique_ptr<Tpdo>> tpdos_;
  std::vector<Tpdo*> tpdo_by_number_;  // [n - 1], null where 1800h + n − 1 is no PDO
};

}  // namespace canfleet::canopen
