#include "orchestrator/broker_telemetry/broker_telemetry.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <stdexcept>

namespace canfleet::broker {

namespace {

/// A 29-bit identifier in BusStats.top_cob_ids carries this bit (SocketCAN's CAN_EFF_FLAG).
constexpr std::uint32_t kExtendedFlag = 0x8000'0000;

}  // namespace

telemetry::BusStatsSnapshot ToSnapshot(const BusStats& stats) {
  telemetry::BusStatsSnapshot s;
  s.bus = stats.name;
  s.bitrate = stats.bitrate;
  // A paced bus runs on its own time line in real time; an unpaced one has no time line.
  s.mode = stats.paced ? "realtime" : "unpaced";
  s.load_percent = static_cast<float>(stats.load_percent);
  s.frames_per_second = static_cast<float>(stats.frames_per_s);
  s.frames_total = stats.frames;
  s.error_frames = stats.error_frames;
  s.node_count = static_cast<std::uint16_t>(std::min<std::size_t>(stats.ports, UINT16_MAX));
  const std::size_t n = std::min(stats.top_ids.size(), s.top_cob_ids.size());
  for (std::size_t i = 0; i < n; ++i) {
    const CobIdStats& id = stats.top_ids[i];
    s.top_cob_ids[i] = {id.extended ? (id.id | kExtendedFlag) : id.id, static_cast<float>(id.frames_per_s)};
  }
  s.top_cob_id_count = static_cast<std::uint8_t>(n);
  return s;
}

BrokerTelemetry::BrokerTelemetry(Broker& broker, Scheduler& scheduler,
                                 telemetry::OrchestratorTelemetry& publisher, BrokerTelemetryOptions options)
    : broker_(broker),
      scheduler_(scheduler),
      publisher_(publisher),
      options_(options),
      timer_(scheduler, [this] {
        Sample();
        timer_.StartAfter(std::chrono::duration_cast<Duration>(options_.period));
      }) {
  if (options_.period <= std::chrono::milliseconds::zero())
    throw std::invalid_argument("BrokerTelemetry: period must be > 0");
  Sample();
  timer_.StartAfter(std::chrono::duration_cast<Duration>(options_.period));
}

BrokerTelemetry::~BrokerTelemetry() {
  for (const auto& bus : published_)
    publisher_.RemoveBus(bus);
}

void BrokerTelemetry::Sample() {
  std::set<std::string> seen;
  for (const std::string& bus : broker_.Buses()) {
    if (bus.empty() || bus.size() > telemetry::kMaxBusName) {
      if (published_.insert(bus).second)  // warn once; never published, so never removed
        spdlog::warn("telemetry: bus name '{}' is longer than {} characters, its BusStats are not published",
                     bus, telemetry::kMaxBusName);
      seen.insert(bus);
      continue;
    }
    telemetry::BusStatsSnapshot snapshot = ToSnapshot(broker_.Stats(bus, telemetry::kMaxTopCobIds));
    if (options_.virtual_time_factor) {
      snapshot.mode = "virtual";
      snapshot.simulated_s = std::chrono::duration<double>(scheduler_.Now().time_since_epoch()).count();
      snapshot.speed_factor = static_cast<float>(options_.virtual_time_factor());
    }
    publisher_.UpdateBusStats(snapshot);
    published_.insert(bus);
    seen.insert(bus);
  }
  for (auto it = published_.begin(); it != published_.end();) {
    if (seen.count(*it)) {
      ++it;
      continue;
    }
    publisher_.RemoveBus(*it);
    it = published_.erase(it);
  }
}

std::uint32_t BrokerTelemetry::PublishFaultInjected(FaultReport report) {
  if (report.fault_id == 0) {
    do {
      report.fault_id = next_fault_id_++;
      if (next_fault_id_ == 0) next_fault_id_ = 0x8000'0000;
    } while (active_.count({report.bus, report.fault_id}));
  }
  Publish(report, telemetry::FaultAction::kInjected);
  const std::uint32_t id = report.fault_id;
  active_[{report.bus, id}] = std::move(report);
  return id;
}

bool BrokerTelemetry::PublishFaultCleared(std::string_view bus, std::uint32_t fault_id) {
  const auto it = active_.find({std::string(bus), fault_id});
  if (it == active_.end()) return false;
  Publish(it->second, telemetry::FaultAction::kCleared);
  active_.erase(it);
  return true;
}

void BrokerTelemetry::Publish(const FaultReport& report, telemetry::FaultAction action) {
  telemetry::FaultSnapshot fault;
  fault.bus = report.bus;
  fault.fault_id = report.fault_id;
  fault.action = action;
  fault.kind = report.kind;
  fault.target_node = report.target_node;
  fault.parameters.assign(
      report.parameters.begin(),
      report.parameters.begin() +
          static_cast<std::ptrdiff_t>(std::min(report.parameters.size(), telemetry::kMaxFaultParameters)));
  fault.bus_time = Now();
  publisher_.PublishFault(std::move(fault));  // throws std::invalid_argument on a bus name too long
}

BusTime BrokerTelemetry::Now() const {
  // The broker's buses run on its scheduler's time line (broker::BusStats::time is the same).
  return std::chrono::duration_cast<BusTime>(scheduler_.Now().time_since_epoch());
}

}  // namespace canfleet::broker
