#pragma once
/// @file One reader per fleet topic, delivering C++ samples: what tools, tests and benchmarks use
/// to watch a fleet. Needs nothing but the DDS domain (no control API).

#include <chrono>
#include <functional>
#include <memory>

#include "telemetry/dds.hpp"
#include "telemetry/samples.hpp"

namespace canfleet::telemetry {

/// Per-sample information from DDS.
struct SampleMeta {
  /// The writer's wall-clock time of the write (DDS source timestamp).
  std::chrono::system_clock::time_point source_time{};
  /// False for an instance-state notification: only the key fields of the sample are set, and the
  /// instance was disposed (its writer left cleanly) or lost all writers (the process died).
  bool valid_data = true;
  /// Instance state is ALIVE. Not only invalid samples can be not alive: when a writer's last
  /// sample and its dispose (or the loss of all writers) reach the reader before it takes, that
  /// valid sample comes with the NOT_ALIVE state and no invalid sample follows. Check `alive` on
  /// every sample.
  bool alive = true;
  bool disposed = false;  ///< NOT_ALIVE_DISPOSED (otherwise, when not alive: no writers)
};

/// Callbacks per topic; an empty one means "not subscribed" for FleetReader's constructor.
struct FleetHandlers {
  std::function<void(const NodeStatusSample&, const SampleMeta&)> node_status{};
  std::function<void(const EmcySample&, const SampleMeta&)> emcy{};
  std::function<void(const IoSnapshotSample&, const SampleMeta&)> io{};
  std::function<void(const BusStatsSample&, const SampleMeta&)> bus_stats{};
  std::function<void(const FaultEventSample&, const SampleMeta&)> fault{};
  std::function<void(const VerdictSample&, const SampleMeta&)> verdict{};
  std::function<void(const ScenarioStatusSample&, const SampleMeta&)> scenario{};
};

class FleetReader {
 public:
  /// Creates a reader for every topic that has a handler (throws DdsError).
  /// @param participant must outlive this object.
  FleetReader(const Participant& participant, FleetHandlers handlers);
  ~FleetReader();
  FleetReader(const FleetReader&) = delete;
  FleetReader& operator=(const FleetReader&) = delete;

  /// Takes every sample available now and calls the handlers; returns how many were taken.
  std::size_t Poll();
  /// Waits until data is available or Wake() is called or `timeout` passes; true unless timed out.
  bool Wait(std::chrono::nanoseconds timeout);
  /// Wakes Wait() from another thread or a signal handler (async-signal-safe).
  void Wake();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_{};
};

}  // namespace canfleet::telemetry
