#include "orchestrator/topology/pdo_warnings.hpp"

#include <cstdio>
#include <utility>

namespace canfleet::topology::detail {

namespace {

using std::chrono::microseconds;
using std::chrono::milliseconds;

constexpr std::uint8_t kCobIdSub = 1;
constexpr std::uint8_t kTypeSub = 2;
constexpr std::uint8_t kEventTimerSub = 5;

// "185h", "18FF1234h (29-bit)": the CAN-ID as CANopen documents write it.
std::string CobIdText(const canopen::PdoCobId& id) {
  char text[24];
  std::snprintf(text, sizeof text, id.extended ? "%XH (29-bit)" : "%03XH", id.can_id);
  std::string out = text;
  out[out.find('H')] = 'h';
  return out;
}

std::string BytesText(std::uint8_t bytes) {
  return std::to_string(bytes) + (bytes == 1 ? " byte" : " bytes");
}

std::string MsText(microseconds t) {
  if (t.count() % 1000 == 0) return std::to_string(t.count() / 1000) + " ms";
  char text[32];
  std::snprintf(text, sizeof text, "%.1f ms", static_cast<double>(t.count()) / 1000.0);
  return text;
}

const Tpdo* Sender(const std::vector<Tpdo>& tpdos, const ConfiguredPort& receiver,
                   const canopen::PdoCobId& id) {
  for (const Tpdo& tpdo : tpdos) {
    // A CAN controller does not receive its own frames.
    if (tpdo.port != &receiver && tpdo.cob_id.SameIdentifier(id)) return &tpdo;
  }
  return nullptr;
}

void CheckTpdos(const Scope& root, const std::string& bus, const BusTraffic& traffic,
                std::vector<TopologyWarning>& warnings) {
  std::vector<const Tpdo*> seen;
  for (const Tpdo& tpdo : traffic.tpdos) {
    if (canopen::IsSynchronous(tpdo.type) && traffic.syncs.empty())
      warnings.push_back(tpdo.port->WarnAt(
          root, tpdo.CommIndex(), kTypeSub,
          tpdo.Name() + " is SYNC-driven (transmission type " + std::to_string(tpdo.type) + ", " +
              tpdo.port->OriginText(tpdo.CommIndex(), kTypeSub) + "), but no node produces SYNC on bus " +
              bus + " (1005h bit 30 with a 1006h period): it is never sent"));
    for (const Tpdo* other : seen) {
      if (!other->cob_id.SameIdentifier(tpdo.cob_id)) continue;
      warnings.push_back(tpdo.port->WarnAt(
          root, tpdo.CommIndex(), kCobIdSub,
          tpdo.Name() + " sends COB-ID " + CobIdText(tpdo.cob_id) + ", as " + other->Name() +
              " does on bus " + bus +
              ": two transmitters of one identifier collide on the wire (a PDO has one producer, CiA 301 "
              "§7.2.2.1)"));
      break;
    }
    seen.push_back(&tpdo);
  }
}

void CheckRpdos(const Scope& root, const ConfiguredPort& port, const BusTraffic& traffic,
                std::vector<TopologyWarning>& warnings) {
  for (std::size_t n = 0; n < canopen::kMaxPdos; ++n) {
    const auto comm = static_cast<std::uint16_t>(canopen::kRpdoCommBase + n);
    if (!port.Has(comm, kCobIdSub)) continue;
    const auto id = canopen::PdoCobId::Decode(port.Unsigned(comm, kCobIdSub));
    const auto type = port.Has(comm, kTypeSub) ? static_cast<std::uint8_t>(port.Unsigned(comm, kTypeSub))
                                               : canopen::kTransmissionEventProfile;
    if (!id.valid || !canopen::IsUsableType(canopen::PdoDirection::kReceive, type)) continue;
    const microseconds deadline = milliseconds(port.Unsigned(comm, kEventTimerSub));
    const std::uint8_t bytes = MappedBytes(port, static_cast<std::uint16_t>(comm + canopen::kMappingOffset));
    const std::string rpdo = port.Name() + " RPDO" + std::to_string(n + 1) + " (" + Hex(comm) + ")";
    const std::string with_deadline = rpdo + " has a " + MsText(deadline) + " deadline (" + Hex(comm) +
                                      " sub 5, " + port.OriginText(comm, kEventTimerSub) + ") on COB-ID " +
                                      CobIdText(id);
    const Tpdo* sender = Sender(traffic.tpdos, port, id);
    if (sender == nullptr) {
      if (deadline.count() == 0) continue;
      std::string why = "no valid TPDO of a node on bus " + port.bus() + " has that COB-ID";
      if (const Tpdo* idle = Sender(traffic.idle_tpdos, port, id))
        why = idle->Name() + " has it, but " + idle->port->node().name +
              " is never started (orchestrator.start_nodes is false and no scenario NMT start names it)";
      warnings.push_back(port.WarnAt(root, comm, kEventTimerSub,
                                     with_deadline + ", which nothing sends: " + why +
                                         ". The deadline starts with the first frame received (CiA 301 "
                                         "§7.5.2.35), so no RPDO timeout is ever reported"));
      continue;
    }
    if (bytes > 0 && sender->bytes != bytes)
      warnings.push_back(
          port.WarnAt(root, comm, kCobIdSub,
                      rpdo + " maps " + BytesText(bytes) + ", but " + sender->Name() + " sends " +
                          BytesText(sender->bytes) + " on COB-ID " + CobIdText(id) +
                          ": every frame raises an RPDO length error (EMCY 8210h/8220h, CiA 301 "
                          "§7.2.2.2)"));
    if (deadline.count() == 0) continue;
    if (sender->period.count() == 0)
      warnings.push_back(port.WarnAt(root, comm, kEventTimerSub,
                                     with_deadline + ", but " + sender->Name() +
                                         " does not send it periodically (no event timer, or SYNC-driven "
                                         "without SYNC): the deadline expires whenever its values hold "
                                         "still"));
    else if (sender->period >= deadline)
      warnings.push_back(port.WarnAt(
          root, comm, kEventTimerSub,
          with_deadline + ", but " + sender->Name() + " sends it every " + MsText(sender->period) +
              ": the deadline expires between two frames while the producer runs"));
  }
}

}  // namespace

std::vector<TopologyWarning> PdoWarnings(const Scope& root, const std::vector<ConfiguredPort>& ports,
                                         const std::map<std::string, BusTraffic>& traffic,
                                         const StartedNodes& started) {
  std::vector<TopologyWarning> warnings;
  for (const auto& [bus, bus_traffic] : traffic)
    CheckTpdos(root, bus, bus_traffic, warnings);
  for (const ConfiguredPort& port : ports) {
    if (!started.Contains(port.node().name)) continue;  // its RPDOs never run
    CheckRpdos(root, port, traffic.at(port.bus()), warnings);
  }
  return warnings;
}

}  // namespace canfleet::topology::detail
