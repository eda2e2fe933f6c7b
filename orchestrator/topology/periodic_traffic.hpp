#pragma once
/// @file What each bus will carry, read from the configured ports (configured_port.hpp): the
/// valid TPDOs with their frame lengths and periods, the heartbeat producers and the SYNC
/// producers. Internal to the loader: the offered load (bus_load.hpp) and the PDO warnings
/// (pdo_warnings.hpp) read it.
///
/// Who sends PDOs follows what the topology does: PDOs run in operational only (CiA 301 §7.3.2.2,
/// table 51), so a node's TPDOs count when it is started — every node with
/// `orchestrator.start_nodes` (the default), else the nodes a scenario NMT start names (or all,
/// for an NMT start without a node). A later stop or pre-operational step is not followed (the
/// load is the peak). Heartbeats and SYNC run in pre-operational too: every configured port counts.

#include <chrono>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "node/canopen/pdo/pdo_config.hpp"
#include "node/canopen/sync/sync_objects.hpp"
#include "orchestrator/topology/canfleet_topology.pb.h"
#include "orchestrator/topology/configured_port.hpp"

namespace canfleet::topology::detail {

/// The nodes the fleet starts (NMT start), by name.
struct StartedNodes {
  bool all = false;
  std::set<std::string> names;
  bool Contains(const std::string& name) const { return all || names.contains(name); }
};
StartedNodes NodesStarted(const Topology& spec);

/// One valid TPDO (CiA 301 §7.5.2.37, 1800h + n - 1; mapping 1A00h + n - 1).
struct Tpdo {
  const ConfiguredPort* port = nullptr;
  int number = 1;  ///< TPDO1 = 1
  canopen::PdoCobId cob_id;
  std::uint8_t type = canopen::kTransmissionEventProfile;
  std::uint8_t bytes = 0;  ///< data length: the mapped bits, rounded up to bytes
  /// Time between two frames when it is sent periodically: the event timer (types 254/255, no
  /// shorter than the inhibit time) or n SYNC periods (types 1..240); zero when it is sent only on
  /// a change (254/255 without event timer), on request (252/253), acyclically (0) or, SYNC-driven,
  /// without a SYNC producer on its bus.
  std::chrono::microseconds period{0};

  std::uint16_t CommIndex() const { return static_cast<std::uint16_t>(canopen::kTpdoCommBase + number - 1); }
  /// "quad-5 TPDO1 (1800h)"
  std::string Name() const;
};

/// A SYNC producer (CiA 301 §7.5.2.5: 1005h bit 30, period 1006h).
struct SyncProducer {
  const ConfiguredPort* port = nullptr;
  std::uint32_t can_id = canopen::kDefaultSyncCobId;
  bool extended = false;
  std::uint8_t bytes = 0;  ///< 1 with a counter (1019h > 1), else 0
  std::chrono::microseconds period{0};
};

/// A heartbeat producer: 1017h > 0.
struct HeartbeatProducer {
  const ConfiguredPort* port = nullptr;
  std::chrono::milliseconds period{0};
};

struct BusTraffic {
  std::vector<Tpdo> tpdos;       ///< of started nodes: they go on the wire
  std::vector<Tpdo> idle_tpdos;  ///< of nodes never started: configured, never sent
  std::vector<HeartbeatProducer> heartbeats;
  std::vector<SyncProducer> syncs;
};

/// Every bus's traffic, by bus name (every bus of the topology has an entry).
std::map<std::string, BusTraffic> TrafficByBus(const Topology& spec, const std::vector<ConfiguredPort>& ports,
                                               const StartedNodes& started);

/// The data length of a PDO's mapping record at `mapping_index`: sub 0 entries' bit lengths (bits
/// 7..0 of each entry, CiA 301 §7.5.2.38), in bytes rounded up; 0 without a mapping.
std::uint8_t MappedBytes(const ConfiguredPort& port, std::uint16_t mapping_index);

}  // namespace canfleet::topology::detail
