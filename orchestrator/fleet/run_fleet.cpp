// `canfleet up`: wires the orchestrator's parts on one event loop and runs it.
#include "orchestrator/fleet/run_fleet.hpp"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <asio/io_context.hpp>
#include <asio/signal_set.hpp>
#include <asio/steady_timer.hpp>
#include <fstream>
#include <iostream>

#include "bus/wire/tcp_endpoint_text.hpp"
#include "clock/asio_scheduler.hpp"
#include "orchestrator/broker/broker.hpp"
#include "orchestrator/broker_telemetry/broker_telemetry.hpp"
#include "orchestrator/control/control_server.hpp"
#include "orchestrator/control/fault_text.hpp"
#include "orchestrator/fleet/fleet.hpp"
#include "orchestrator/socketcand/server.hpp"
#include "orchestrator/topology/topology_loader.hpp"
#include "orchestrator/transport/broker_server.hpp"
#include "telemetry/cli_options.hpp"
#include "telemetry/orchestrator_telemetry.hpp"

namespace canfleet::fleet {

namespace {

/// canfleet-node: asked for, else beside this executable, else on PATH.
std::filesystem::path FindNodeBinary(const std::filesystem::path& asked) {
  if (!asked.empty()) {
    if (::access(asked.c_str(), X_OK) != 0)
      throw std::runtime_error("--node-binary " + asked.string() + ": not an executable");
    return std::filesystem::absolute(asked);
  }
  std::error_code ec;
  const auto self = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const auto beside = self.parent_path() / "canfleet-node";
    if (::access(beside.c_str(), X_OK) == 0) return beside;
  }
  if (const char* path = std::getenv("PATH")) {
    std::string_view rest(path);
    while (!rest.empty()) {
      const auto colon = rest.find(':');
      const std::filesystem::path candidate = std::filesystem::path(rest.substr(0, colon)) / "canfleet-node";
      if (::access(candidate.c_str(), X_OK) == 0) return candidate;
      if (colon == std::string_view::npos) break;
      rest.remove_prefix(colon + 1);
    }
  }
  throw std::runtime_error("canfleet-node not found beside canfleet nor on PATH (use --node-binary)");
}

/// Written then renamed, so a reader never sees half a file.
void WriteStateFile(const std::filesystem::path& path, const std::string& control, const std::string& broker,
                    const char* state) {
  if (path.empty()) return;
  const auto tmp = path.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << "control " << control << "\nbroker " << broker << "\nstate " << state << "\n";
  }
  std::filesystem::rename(tmp, path);
}

}  // namespace

int RunFleet(const UpOptions& options) {
  topology::LoadedTopology loaded;
  try {
    loaded = topology::LoadTopology(options.topology);
  } catch (const std::exception& e) {
    std::cerr << "canfleet up: " << e.what() << "\n";
    return 2;
  }
  auto& spec = loaded.spec;
  if (options.control) spec.mutable_orchestrator()->set_control(*options.control);
  if (options.listen) {
    spec.mutable_orchestrator()->clear_listen();
    spec.mutable_orchestrator()->add_listen(*options.listen);
  }

  spdlog::set_level(spdlog::level::from_str(options.log_level));
  asio::io_context io(1);
  AsioScheduler scheduler(io);
  broker::Broker broker(scheduler);
  transport::BrokerServer server(io, broker);
  socketcand::ServerOptions socketcand_options;
  socketcand_options.bind_address = options.socketcand_bind;
  socketcand::Server socketcand(io, broker, scheduler, socketcand_options);
  std::unique_ptr<Fleet> fleet;
  std::unique_ptr<control::ControlServer> control_server;
  std::string control_endpoint, broker_endpoint;
  try {
    for (const auto& bus : spec.bus()) {
      broker::BusConfig config;
      config.name = bus.name();
      config.bitrate = bus.bitrate();
      config.paced = !bus.unpaced();
      config.auto_recover = !bus.manual_recovery();
      broker.AddBus(config);
      spdlog::info("bus {}: {} bit/s, {}", config.name, config.bitrate, config.paced ? "paced" : "unpaced");
      if (bus.socketcand_port() != 0) {
        const auto port = socketcand.Serve(bus.name(), static_cast<std::uint16_t>(bus.socketcand_port()));
        spdlog::info("bus {}: socketcand on port {}", bus.name(), port);
      }
    }
    for (const auto& listen : spec.orchestrator().listen())
      server.Listen(wire::Endpoint::Parse(listen));
    broker_endpoint = server.Endpoints().front().ToString();

    FleetOptions fleet_options;
    fleet_options.topology = spec;
    fleet_options.broker_endpoint = broker_endpoint;
    fleet_options.start_processes = !options.no_start;
    if (!options.no_start) fleet_options.node_binary = FindNodeBinary(options.node_binary);
    fleet_options.node_arguments = telemetry::DdsArguments(options.dds);
    fleet = std::make_unique<Fleet>(io, scheduler, broker, server, std::move(fleet_options));
    control_server = std::make_unique<control::ControlServer>(io, *fleet);
    const auto bound = control_server->Listen(spec.orchestrator().control());
    control_endpoint = "tcp://" + wire::TcpEndpointText(bound);
  } catch (const std::exception& e) {
    spdlog::critical("{}", e.what());
    return 2;
  }
  spdlog::info("control API on {}, nodes connect to {}", control_endpoint, broker_endpoint);

  // Telemetry: the buses' statistics and the fault event log on DDS (the nodes publish their own).
  // Declared after the broker and destroyed before it; the fleet runs without it if DDS fails.
  std::optional<telemetry::Participant> participant;
  std::optional<telemetry::OrchestratorTelemetry> publisher;
  std::optional<broker::BrokerTelemetry> bus_telemetry;
  if (options.telemetry) {
    try {
      participant.emplace(options.dds);
      publisher.emplace(*participant);
      bus_telemetry.emplace(broker, scheduler, *publisher);
      spdlog::info("telemetry: BusStats and FaultEvents on DDS domain {}", options.dds.domain_id);
    } catch (const std::exception& e) {
      spdlog::error("telemetry: {}; running without it", e.what());
      bus_telemetry.reset();
      publisher.reset();
      participant.reset();
    }
  }
  fleet->OnFaultEvent([&](const control::FaultStatus& status, bool started) {
    if (!bus_telemetry) return;
    try {
      if (started) {
        broker::FaultReport report;
        report.bus = status.spec().bus();
        report.fault_id = status.fault_id();
        report.kind = std::string(control::FaultKindName(status.spec().kind()));
        report.parameters = {{"summary", status.summary()}};
        bus_telemetry->PublishFaultInjected(report);
      } else {
        bus_telemetry->PublishFaultCleared(status.spec().bus(), status.fault_id());
      }
    } catch (const std::exception& e) {
      spdlog::warn("telemetry: fault event {}: {}", status.fault_id(), e.what());
    }
  });
  WriteStateFile(options.ready_file, control_endpoint, broker_endpoint, "starting");

  bool stopping = false;
  asio::steady_timer drain(io);
  auto shutdown = [&](const char* why) {
    if (stopping) return;
    stopping = true;
    spdlog::info("{}: stopping the fleet", why);
    fleet->Stop([&] {
      spdlog::info("every node process has stopped");
      control_server->Close();
      socketcand.Stop();
      server.Close();
      // Let the farewells leave before the loop ends.
      drain.expires_after(std::chrono::milliseconds(200));
      drain.async_wait([&](const asio::error_code&) { io.stop(); });
    });
  };
  fleet->OnReady([&] { WriteStateFile(options.ready_file, control_endpoint, broker_endpoint, "ready"); });
  fleet->OnShutdownRequest([&] { shutdown("canfleet down"); });
  asio::signal_set signals(io, SIGINT, SIGTERM);
  signals.async_wait([&](const asio::error_code& ec, int signal) {
    if (!ec) shutdown(signal == SIGINT ? "SIGINT" : "SIGTERM");
  });
  fleet->Start();
  io.run();
  control_server.reset();
  fleet.reset();
  bus_telemetry.reset();
  spdlog::info("stopped");
  return 0;
}

}  // namespace canfleet::fleet
