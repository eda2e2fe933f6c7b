#include "telemetry/fleet_reader.hpp"

#include <optional>

#include "telemetry/topics.hpp"

namespace canfleet::telemetry {

namespace {

SampleMeta ToMeta(const dds_sample_info_t& info) {
  SampleMeta meta;
  meta.source_time =
      std::chrono::system_clock::time_point(std::chrono::duration_cast<std::chrono::system_clock::duration>(
          std::chrono::nanoseconds(info.source_timestamp)));
  meta.valid_data = info.valid_data;
  meta.alive = info.instance_state == DDS_IST_ALIVE;
  meta.disposed = info.instance_state == DDS_IST_NOT_ALIVE_DISPOSED;
  return meta;
}

/// A subscription to one topic: reader plus handler, created only if the handler is set.
template <typename T, typename S>
struct Subscription {
  Subscription(const Participant& participant, std::function<void(const S&, const SampleMeta&)> fn)
      : handler(std::move(fn)) {
    if (handler) {
      topic.emplace(participant);
      reader.emplace(participant, *topic);
    }
  }
  std::size_t Poll() {
    if (!reader) return 0;
    const dds_return_t n = reader->TakeAll(
        [&](const T& sample, const dds_sample_info_t& info) { handler(FromDds(sample), ToMeta(info)); });
    return n > 0 ? static_cast<std::size_t>(n) : 0;
  }
  std::function<void(const S&, const SampleMeta&)> handler;
  std::optional<Topic<T>> topic;
  std::optional<Reader<T>> reader;
};

}  // namespace

struct FleetReader::Impl {
  Impl(const Participant& participant, FleetHandlers h)
      : node_status(participant, std::move(h.node_status)),
        emcy(participant, std::move(h.emcy)),
        io(participant, std::move(h.io)),
        bus_stats(participant, std::move(h.bus_stats)),
        fault(participant, std::move(h.fault)),
        verdict(participant, std::move(h.verdict)),
        scenario(participant, std::move(h.scenario)),
        waitset(participant) {
    if (node_status.reader) waitset.AttachDataAvailable(node_status.reader->handle());
    if (emcy.reader) waitset.AttachDataAvailable(emcy.reader->handle());
    if (io.reader) waitset.AttachDataAvailable(io.reader->handle());
    if (bus_stats.reader) waitset.AttachDataAvailable(bus_stats.reader->handle());
    if (fault.reader) waitset.AttachDataAvailable(fault.reader->handle());
    if (verdict.reader) waitset.AttachDataAvailable(verdict.reader->handle());
    if (scenario.reader) waitset.AttachDataAvailable(scenario.reader->handle());
  }
  Subscription<canfleet_telemetry_NodeStatus, NodeStatusSample> node_status;
  Subscription<canfleet_telemetry_Emcy, EmcySample> emcy;
  Subscription<canfleet_telemetry_IoSnapshot, IoSnapshotSample> io;
  Subscription<canfleet_telemetry_BusStats, BusStatsSample> bus_stats;
  Subscription<canfleet_telemetry_FaultEvent, FaultEventSample> fault;
  Subscription<canfleet_telemetry_Verdict, VerdictSample> verdict;
  Subscription<canfleet_telemetry_ScenarioStatus, ScenarioStatusSample> scenario;
  WaitSet waitset;  // deleted before the readers' conditions (declared last)
};

FleetReader::FleetReader(const Participant& participant, FleetHandlers handlers)
    : impl_(std::make_unique<Impl>(participant, std::move(handlers))) {}

FleetReader::~FleetReader() = default;

std::size_t FleetReader::Poll() {
  // Events first: an EMCY and the status it changed arrive in that order at the handlers.
  return impl_->emcy.Poll() + impl_->fault.Poll() + impl_->verdict.Poll() + impl_->node_status.Poll() +
         impl_->io.Poll() + impl_->bus_stats.Poll() + impl_->scenario.Poll();
}

bool FleetReader::Wait(std::chrono::nanoseconds timeout) {
  return impl_->waitset.Wait(timeout);
}

void FleetReader::Wake() {
  impl_->waitset.Trigger();
}

}  // namespace canfleet::telemetry
