#pragma once
/// @file What the PDOs of one PdoService share: the seams, the counters and the SYNC timing.

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>

#include "bus/bus_port.hpp"
#include "clock/scheduler.hpp"
#include "node/canopen/common/comm_error.hpp"
#include "node/canopen/od/object_dictionary.hpp"
#include "node/canopen/pdo/pdo_mapping.hpp"

namespace canfleet::canopen {

/// Traffic counters of a PdoService (for telemetry and tests).
struct PdoCounters {
  std::uint64_t rpdo_received =
      0;                           ///< frames taken by a usable RPDO while operational, whatever their length
  std::uint64_t rpdo_applied = 0;  ///< received data written to the dictionary (sync RPDOs: at the SYNC)
  std::uint64_t tpdo_sent = 0;     ///< TPDO frames the bus port accepted
};

/// Shared by a PdoService and its Rpdo/Tpdo objects; owned by the service.
struct PdoContext {
  ObjectDictionary& od;
  BusPort& port;
  Scheduler& scheduler;
  CommErrorSink& errors;
  PdoCounters& counters;
  const SubObject* window = nullptr;  ///< 1007h synchronous window length, µs; may be null
  std::optional<TimePoint> last_sync;
  /// Device veto on a TPDO about to be sent (PdoService::SetTpdoGate): false = not sent. Empty:
  /// every TPDO is sent.
  std::function<bool(std::size_t tpdo_number, std::span<const MappedObject> entries)> tpdo_gate;

  /// CiA 301 §7.5.2.7: true within 1007h µs (inclusive) after the last SYNC, always when 1007h is
  /// 0 or absent, never before the first SYNC when a window is set.
  bool InsideSyncWindow() const {
    const std::uint64_t window_us = window ? DecodeUnsignedLe(window->value) : 0;
    if (window_us == 0) return true;
    if (!last_sync) return false;
    return scheduler.Now() - *last_sync <= std::chrono::microseconds(window_us);
  }
};

}  // namespace canfleet::canopen
