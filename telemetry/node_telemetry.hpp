#pragma once
/// @file What a node process publishes: NodeStatus and IoSnapshot (on change and every period) and
/// Emcy events. See publisher_loop.hpp for the threading: the caller only copies a snapshot.
///
/// Use from the node's event loop:
/// @code
///   telemetry::Participant participant(dds_options);             // once per process
///   telemetry::NodeTelemetry telemetry(participant, {.bus = "can0", .node_id = 5, .device = "quad"});
///   telemetry::NodeStatusSnapshot status;                       // keep one, fill what changed
///   status.nmt_state = NmtState::kOperational; ...
///   telemetry.UpdateStatus(status);                             // on every change, or from a timer
///   telemetry.PublishEmcy({.code = 0x8130, .error_register = 0x11, .bus_time = t});
/// @endcode

#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "telemetry/dds.hpp"
#include "telemetry/publisher_loop.hpp"
#include "telemetry/types.hpp"

namespace canfleet::telemetry {

/// The changing part of a node's status, filled by the caller. Fixed size (about 1 kB, no heap),
/// so handing it over is one copy. The identity (bus, node-id, device) is in the options.
struct NodeStatusSnapshot {
  NmtState nmt_state = NmtState::kInitialising;
  std::uint8_t error_register = 0;  ///< 1001h
  ControllerState controller_state = ControllerState::kErrorActive;
  std::uint16_t tec = 0;
  std::uint8_t rec = 0;
  std::uint16_t heartbeat_producer_ms = 0;  ///< 1017h
  std::uint8_t heartbeat_consumer_count = 0;
  std::array<HeartbeatConsumerInfo, kMaxHeartbeatConsumers> heartbeat_consumers{};
  std::uint64_t rpdo_count = 0;
  std::uint64_t tpdo_count = 0;
};

/// True if `a` and `b` differ in anything but the PDO counters: what "on change" means. Counters
/// move with every PDO and go out with the periodic publication.
bool StatusChanged(const NodeStatusSnapshot& a, const NodeStatusSnapshot& b);

/// A simulated input or output: name (e.g. "IN1.voltage_mV") and unit (e.g. "mV"). A bool or an
/// enum has its words by value: {"false", "true"}, or the enum's choices in order; its value is
/// the index of the word, and IoValue.text carries the word (copied by the publisher, no
/// allocation).
struct IoChannel {
  std::string name;
  std::string unit;
  std::vector<std::string> words{};
};

struct NodeTelemetryOptions {
  std::string bus{};  ///< at most kMaxBusName characters
  std::uint8_t node_id = 0;
  std::string device = "generic";
  /// The node's name in its topology (canfleet-node --name); at most kMaxNodeName characters
  /// are published.
  std::string name{};
  /// Every instance is republished at least this often (uptime, counters, liveliness for readers).
  std::chrono::milliseconds period{1000};
  /// Snapshots are sampled at most this often; changes in between are coalesced (latest wins).
  std::chrono::milliseconds min_interval{20};
  /// The node's simulated I/O channels, in the order UpdateIo() gives their values.
  std::vector<IoChannel> inputs{};
  std::vector<IoChannel> outputs{};
  /// EMCYs waiting for the publisher thread; beyond this they are counted as dropped.
  std::size_t emcy_queue = 64;
  /// The node's own clock for the uptime (its Now() must be safe to read from the publisher's
  /// thread, as AsioScheduler's and GrantedScheduler's are): in virtual time the uptime is then
  /// simulated time. nullptr: the publisher loop's clock.
  const Scheduler* uptime_clock = nullptr;
};

/// Counters for tests and benchmarks.
struct PublisherStats {
  std::uint64_t state_writes = 0;  ///< NodeStatus/IoSnapshot (or BusStats) samples written
  std::uint64_t event_writes = 0;  ///< Emcy (or FaultEvent) samples written
  std::uint64_t write_errors = 0;
  std::uint64_t events_dropped = 0;  ///< queue full
};

class NodeTelemetry final : private PublisherLoop {
 public:
  /// Creates the topics and writers (throws DdsError) and starts the publisher thread.
  /// Throws std::invalid_argument for a bus name or I/O list beyond the IDL bounds.
  /// @param participant must outlive this object.
  NodeTelemetry(const Participant& participant, NodeTelemetryOptions options);
  /// The same on simulated time (tests): no thread; publication runs on `scheduler`'s timers, from
  /// the thread that advances it, which is also the only thread that may call the methods below.
  NodeTelemetry(const Participant& participant, NodeTelemetryOptions options, Scheduler& scheduler);
  /// Writes any pending change, stops the thread, deletes the writers (which disposes the node's
  /// instances: monitors see it leave).
  ~NodeTelemetry();
  NodeTelemetry(const NodeTelemetry&) = delete;
  NodeTelemetry& operator=(const NodeTelemetry&) = delete;

  /// Hands over the current status. Any thread; never blocks on DDS.
  void UpdateStatus(const NodeStatusSnapshot& status);
  /// Hands over the current I/O values, in the order of options.inputs/outputs (extra values are
  /// ignored, missing ones keep their last value). Any thread; no allocation.
  void UpdateIo(std::span<const double> inputs, std::span<const double> outputs);
  /// Queues an EMCY for immediate publication and makes it the status's last EMCY.
  void PublishEmcy(const EmcyInfo& emcy);

  using PublisherLoop::Flush;
  PublisherStats stats() const;

 private:
  struct Impl;
  void Init(const Participant& participant, NodeTelemetryOptions options);
  void ConsumeLocked(bool inputs) override;
  TimePoint Publish(TimePoint now, bool force) override;

  std::unique_ptr<Impl> impl_;
};

}  // namespace canfleet::telemetry
