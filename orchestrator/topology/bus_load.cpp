#include "orchestrator/topology/bus_load.hpp"

#include <chrono>

#include "bus/physics/frame_timing.hpp"

namespace canfleet::topology::detail {

namespace {

constexpr std::uint8_t kHeartbeatBytes = 1;  // CiA 301 §7.2.8.3.2: the NMT state

// Bits per second of one frame every `period`.
template <typename Duration>
double BitsPerSecond(std::uint8_t bytes, bool extended, Duration period) {
  const double seconds = std::chrono::duration<double>(period).count();
  return static_cast<double>(MaxFrameBits(bytes, extended)) / seconds;
}

}  // namespace

BusLoad OfferedLoad(const Bus& bus, const BusTraffic& traffic) {
  BusLoad load;
  load.bus = bus.name();
  load.bitrate = bus.bitrate();
  load.unpaced = bus.unpaced();
  if (load.bitrate == 0) return load;
  double tpdos = 0, heartbeats = 0, sync = 0;
  for (const Tpdo& tpdo : traffic.tpdos) {
    if (tpdo.period.count() > 0) tpdos += BitsPerSecond(tpdo.bytes, tpdo.cob_id.extended, tpdo.period);
  }
  for (const HeartbeatProducer& producer : traffic.heartbeats)
    heartbeats += BitsPerSecond(kHeartbeatBytes, false, producer.period);
  for (const SyncProducer& producer : traffic.syncs)
    sync += BitsPerSecond(producer.bytes, producer.extended, producer.period);
  load.tpdos = tpdos / load.bitrate;
  load.heartbeats = heartbeats / load.bitrate;
  load.sync = sync / load.bitrate;
  return load;
}

std::string OverloadReason(const BusLoad& load) {
  if (load.unpaced || load.Total() <= 1.0) return "";
  return "bus " + load.bus + ": periodic traffic offers " + load.Describe() +
         ": configuration SDOs and low-priority frames will starve";
}

}  // namespace canfleet::topology::detail
