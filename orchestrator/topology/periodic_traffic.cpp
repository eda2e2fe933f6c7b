#include "orchestrator/topology/periodic_traffic.hpp"

#include <algorithm>

namespace canfleet::topology::detail {

namespace {

using std::chrono::microseconds;
using std::chrono::milliseconds;

constexpr std::uint16_t kHeartbeatProducerIndex = 0x1017;
constexpr std::uint8_t kMaxPdoBytes = 8;

// Communication record sub-indexes (CiA 301 §7.5.2.37).
constexpr std::uint8_t kCobIdSub = 1;
constexpr std::uint8_t kTypeSub = 2;
constexpr std::uint8_t kInhibitSub = 3;  // × 100 µs
constexpr std::uint8_t kEventTimerSub = 5;

std::uint8_t Type(const ConfiguredPort& port, std::uint16_t comm) {
  return port.Has(comm, kTypeSub) ? static_cast<std::uint8_t>(port.Unsigned(comm, kTypeSub))
                                  : canopen::kTransmissionEventProfile;
}

// The TPDOs of one port that are valid, of a type a TPDO runs, and map something (an empty
// mapping sends nothing); period left for SYNC-driven ones (the bus's SYNC is known later).
std::vector<Tpdo> ValidTpdos(const ConfiguredPort& port) {
  std::vector<Tpdo> out;
  for (std::size_t n = 0; n < canopen::kMaxPdos; ++n) {
    const auto comm = static_cast<std::uint16_t>(canopen::kTpdoCommBase + n);
    if (!port.Has(comm, kCobIdSub)) continue;
    Tpdo tpdo;
    tpdo.port = &port;
    tpdo.number = static_cast<int>(n + 1);
    tpdo.cob_id = canopen::PdoCobId::Decode(port.Unsigned(comm, kCobIdSub));
    tpdo.type = Type(port, comm);
    tpdo.bytes = MappedBytes(port, static_cast<std::uint16_t>(comm + canopen::kMappingOffset));
    if (!tpdo.cob_id.valid || !canopen::IsUsableType(canopen::PdoDirection::kTransmit, tpdo.type) ||
        tpdo.bytes == 0)
      continue;
    if (canopen::IsEventDriven(tpdo.type)) {
      const milliseconds timer(port.Unsigned(comm, kEventTimerSub));
      const microseconds inhibit(100ULL * port.Unsigned(comm, kInhibitSub));
      if (timer.count() > 0) tpdo.period = std::max<microseconds>(timer, inhibit);
    }
    out.push_back(tpdo);
  }
  return out;
}

}  // namespace

StartedNodes NodesStarted(const Topology& spec) {
  StartedNodes started;
  started.all = !spec.orchestrator().has_start_nodes() || spec.orchestrator().start_nodes();
  for (const Step& step : spec.scenario()) {
    if (!step.has_nmt() || step.nmt().action() != control::NMT_START) continue;
    if (step.nmt().node().empty())
      started.all = true;
    else
      started.names.insert(step.nmt().node());
  }
  return started;
}

std::string Tpdo::Name() const {
  return port->Name() + " TPDO" + std::to_string(number) + " (" + Hex(CommIndex()) + ")";
}

std::uint8_t MappedBytes(const ConfiguredPort& port, std::uint16_t mapping_index) {
  if (!port.Has(mapping_index, 0)) return 0;
  const auto entries = static_cast<std::uint8_t>(port.Unsigned(mapping_index, 0));
  std::uint32_t bits = 0;
  for (std::uint8_t sub = 1; sub <= entries && sub <= canopen::kMaxMappingEntries; ++sub)
    bits += port.Unsigned(mapping_index, sub) & 0xFF;
  return static_cast<std::uint8_t>(std::min<std::uint32_t>((bits + 7) / 8, kMaxPdoBytes));
}

std::map<std::string, BusTraffic> TrafficByBus(const Topology& spec, const std::vector<ConfiguredPort>& ports,
                                               const StartedNodes& started) {
  std::map<std::string, BusTraffic> traffic;
  for (const Bus& bus : spec.bus())
    traffic[bus.name()];
  for (const ConfiguredPort& port : ports) {
    BusTraffic& bus = traffic[port.bus()];
    if (const milliseconds period(port.Unsigned(kHeartbeatProducerIndex, 0)); period.count() > 0)
      bus.heartbeats.push_back({&port, period});
    const auto sync = canopen::SyncCobId::Decode(static_cast<std::uint32_t>(
        port.Has(canopen::kCobIdSyncIndex, 0) ? port.Unsigned(canopen::kCobIdSyncIndex, 0)
                                              : canopen::kDefaultSyncCobId));
    const microseconds sync_period(port.Unsigned(canopen::kCommunicationCyclePeriodIndex, 0));
    if (sync.producer && sync_period.count() > 0) {
      const auto overflow = static_cast<std::uint8_t>(port.Unsigned(canopen::kSyncCounterOverflowIndex, 0));
      bus.syncs.push_back({&port, sync.can_id, sync.extended,
                           static_cast<std::uint8_t>(canopen::SyncCounterInUse(overflow) ? 1 : 0),
                           sync_period});
    }
    auto& list = started.Contains(port.node().name) ? bus.tpdos : bus.idle_tpdos;
    for (const Tpdo& tpdo : ValidTpdos(port))
      list.push_back(tpdo);
  }
  // SYNC-driven TPDOs (types 1..240) are sent every n-th SYNC of their bus's producer.
  for (auto& [name, bus] : traffic) {
    if (bus.syncs.empty()) continue;
    const microseconds sync_period = bus.syncs.front().period;
    for (auto* list : {&bus.tpdos, &bus.idle_tpdos}) {
      for (Tpdo& tpdo : *list) {
        if (tpdo.type >= 1 && tpdo.type <= canopen::kTransmissionSyncMaxCycle)
          tpdo.period = sync_period * tpdo.type;
      }
    }
  }
  return traffic;
}

}  // namespace canfleet::topology::detail
