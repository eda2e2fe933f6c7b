#pragma once
/// @file What every process that hosts the broker wires the same way: canfleet-broker (the broker
/// alone, broker_main.cpp) and `canfleet up` (the fleet, fleet/run_fleet.cpp) differ only in what
/// they add on top.
///
///     asio::io_context io(1);
///     host::BrokerHost host(io);
///     host.AddBus({.name = "can0", .bitrate = 500'000});
///     host.Listen(wire::Endpoint::Parse("tcp://127.0.0.1:29600"));
///     host.StartTelemetry(dds, std::chrono::seconds(1));   // runs without it if DDS fails
///     host.OnSignal([&](const char* name) { host.Stop(); });
///     io.run();
///
/// Threading: everything on the thread that runs `io`, like the broker.

#include <asio/io_context.hpp>
#include <asio/signal_set.hpp>
#include <asio/steady_timer.hpp>
#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "bus/wire/endpoint.hpp"
#include "clock/asio_scheduler.hpp"
#include "clock/granted_scheduler.hpp"
#include "clock/wall_clock.hpp"
#include "orchestrator/broker/broker.hpp"
#include "orchestrator/broker_telemetry/broker_telemetry.hpp"
#include "orchestrator/socketcand/server.hpp"
#include "orchestrator/transport/broker_server.hpp"
#include "orchestrator/transport/time_conductor.hpp"
#include "telemetry/dds.hpp"
#include "telemetry/orchestrator_telemetry.hpp"

namespace canfleet::host {

/// How the host's buses keep time.
struct HostTime {
  /// Lock-step virtual time (transport/time_conductor.hpp): the broker owns the clock and grants
  /// it to the nodes. False: real time.
  bool virtual_time = false;
  transport::TimeConductorOptions conductor;
};

/// Parses --speed: "max" (0) or a positive factor of real time ("10", "0.5"). Throws
/// std::invalid_argument.
double ParseSpeed(const std::string& text);

/// How long (real time) a host in virtual time waits for its node processes to join before time
/// starts anyway (TimeConductor::HoldUntilJoined).
inline constexpr std::chrono::seconds kJoinTimeout{60};

class BrokerHost {
 public:
  /// The scheduler on `io`, the broker, the node transport and the socketcand server (serving no
  /// bus yet); the process's wall-clock origin is read now, once, and given to socketcand
  /// (captures take it from wall_origin()). In virtual time the scheduler is granted by the time
  /// conductor, and the wall-clock origin is the Unix epoch: a capture's timestamps are simulated
  /// seconds, the same on every run.
  explicit BrokerHost(asio::io_context& io, socketcand::ServerOptions socketcand_options = {},
                      HostTime time = {});
  /// Telemetry goes first (its BusStats are disposed), then the servers and the broker.
  ~BrokerHost();
  BrokerHost(const BrokerHost&) = delete;
  BrokerHost& operator=(const BrokerHost&) = delete;

  Scheduler& scheduler() { return *scheduler_; }
  /// The time conductor in virtual time, else nullptr.
  transport::TimeConductor* conductor() { return conductor_.get(); }
  broker::Broker& broker() { return broker_; }
  transport::BrokerServer& server() { return server_; }
  /// Wall-clock time of scheduler time 0 for everything that stamps frames (clock/wall_clock.hpp).
  WallTime wall_origin() const { return wall_origin_; }

  /// Adds a bus (Broker::AddBus: throws std::invalid_argument) and logs it.
  void AddBus(const broker::BusConfig& config);
  /// Serves `bus` with the socketcand protocol on `port` (0: any) and logs it; returns the port.
  /// Throws std::invalid_argument in virtual time: a socketcand client lives in real time.
  std::uint16_t ServeSocketcand(const std::string& bus, std::uint16_t port);
  /// Where nodes connect (BrokerServer::Listen); returns the bound endpoint.
  wire::Endpoint Listen(const wire::Endpoint& endpoint);
  /// The bound node endpoints, in Listen order.
  const std::vector<wire::Endpoint>& Endpoints() const { return server_.Endpoints(); }

  /// BusStats of every bus on DDS, sampled and republished every `period`, and the FaultEvents
  /// published through telemetry(). When DDS cannot start, says why and runs without: the buses
  /// matter more than their monitoring. Returns whether telemetry runs.
  bool StartTelemetry(const telemetry::DdsOptions& dds, std::chrono::milliseconds period);
  /// The running telemetry, or nullptr.
  broker::BrokerTelemetry* telemetry() { return bus_telemetry_ ? &*bus_telemetry_ : nullptr; }
  /// The running telemetry's publisher (for what else the orchestrator publishes: its scenario),
  /// or nullptr.
  telemetry::OrchestratorTelemetry* publisher() { return bus_telemetry_ ? &*publisher_ : nullptr; }

  /// `handler` runs, with "SIGINT" or "SIGTERM", when the process is asked to stop.
  void OnSignal(std::function<void(const char* name)> handler);
  /// Stops serving (idempotent): socketcand and node sessions are closed (nodes are told "broker
  /// shutting down" and detach), the farewells get 200 ms to leave, then the event loop stops.
  void Stop();

 private:
  asio::io_context& io_;
  std::unique_ptr<Scheduler> scheduler_;
  WallTime wall_origin_;
  broker::Broker broker_;
  std::unique_ptr<transport::TimeConductor> conductor_;
  transport::BrokerServer server_;
  socketcand::Server socketcand_;
  // Declared after the broker and the scheduler they sample: destroyed first.
  std::optional<telemetry::Participant> participant_;
  std::optional<telemetry::OrchestratorTelemetry> publisher_;
  std::optional<broker::BrokerTelemetry> bus_telemetry_;
  asio::signal_set signals_;
  asio::steady_timer drain_;
  bool stopping_ = false;
};

}  // namespace canfleet::host
