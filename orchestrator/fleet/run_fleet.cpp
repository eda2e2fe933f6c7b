// `canfleet up`: the broker's host (host::BrokerHost, as canfleet-broker has it) plus the fleet and
// the control API, on one event loop.
#include "orchestrator/fleet/run_fleet.hpp"
#include "orchestrator/fleet/child_process.hpp"

#include <spdlog/spdlog.h>

#include <unistd.h>
#include <csignal>

#include <asio/io_context.hpp>
#include <fstream>
#include <iostream>

#include "bus/wire/tcp_endpoint_text.hpp"
#include "orchestrator/control/control_server.hpp"
#include "orchestrator/control/fault_text.hpp"
#include "orchestrator/fleet/fleet.hpp"
#include "orchestrator/host/broker_host.hpp"
#include "orchestrator/topology/topology_loader.hpp"
#include "telemetry/cli_options.hpp"

namespace canfleet::fleet {

namespace {

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

std::size_t NodeProcesses(const topology::Topology& spec) {
  return static_cast<std::size_t>(spec.node_size());
}

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
  if (options.state_root) {
    const std::filesystem::path old_root = spec.orchestrator().state_root();
    const std::filesystem::path root = std::filesystem::absolute(*options.state_root);
    spec.mutable_orchestrator()->set_state_root(root.string());
    for (auto& node : *spec.mutable_node())
      if (std::filesystem::path(node.state_dir()) == old_root / node.name())
        node.set_state_dir((root / node.name()).string());
  }
  if (options.seed) spec.mutable_time()->set_seed(*options.seed);

  spdlog::set_level(spdlog::level::from_str(options.log_level));
  // What the loader found that cannot work (topology_warnings.hpp), and each bus's periodic load.
  for (const auto& warning : loaded.warnings)
    spdlog::warn("{}", warning.Message());
  for (const auto& load : loaded.loads)
    spdlog::info("bus {}: periodic traffic offers {}", load.bus, load.Describe());
  asio::io_context io(1);
  socketcand::ServerOptions socketcand_options;
  socketcand_options.bind_address = options.socketcand_bind;
  host::HostTime time;
  try {
    time = FleetTime(spec, options.time);
  } catch (const std::exception& e) {
    std::cerr << "canfleet up: " << e.what() << "\n";
    return 2;
  }
  if (options.driven && !time.virtual_time) {
    std::cerr << "canfleet up: --driven needs virtual time (--time virtual)\n";
    return 2;
  }
  // A test steps driven time and may act on whatever it sees at once: one grant for all from the
  // start, so that no process stands ahead of the time the test sees (per-node lookahead would have
  // them there when the fleet becomes ready and time stops for the driver).
  if (options.driven) time.conductor.lookahead = transport::TimeConductorOptions::Lookahead::kGlobal;
  host::BrokerHost host(io, socketcand_options, time);
  std::unique_ptr<Fleet> fleet;
  std::unique_ptr<BoundaryControlHandler> boundary;
  std::unique_ptr<control::ControlServer> control_server;
  std::string control_endpoint, broker_endpoint;
  try {
    for (const auto& bus : spec.bus()) {
      host.AddBus({.name = bus.name(),
                   .bitrate = bus.bitrate(),
                   .paced = !bus.unpaced(),
                   .auto_recover = !bus.manual_recovery()});
      if (bus.socketcand_port() != 0)
        host.ServeSocketcand(bus.name(), static_cast<std::uint16_t>(bus.socketcand_port()));
    }
    host.server().SetToken(options.token);
    for (const auto& listen : spec.orchestrator().listen())
      host.Listen(wire::Endpoint::Parse(listen));
    broker_endpoint = host.Endpoints().front().ToString();

    FleetOptions fleet_options;
    fleet_options.topology = spec;
    fleet_options.broker_endpoint = broker_endpoint;
    fleet_options.start_processes = !options.no_start;
    if (!options.no_start) fleet_options.node_binary = FindNodeBinary(options.node_binary);
    fleet_options.node_arguments = telemetry::DdsArguments(options.dds);
    fleet_options.wall_origin = host.wall_origin();
    fleet_options.repeat_scenario = true;
    fleet_options.seed = spec.time().seed();
    fleet_options.scenario_source = options.topology.string();
    fleet_options.step_lines = loaded.step_lines;
    if (!options.capture_dir.empty())
      fleet_options.capture_folders = CaptureFoldersAt(options.capture_dir, spec.orchestrator().state_root());
    UseHostTime(fleet_options, host.conductor());
    fleet =
        std::make_unique<Fleet>(io, host.scheduler(), host.broker(), host.server(), std::move(fleet_options));
    control_server =
        std::make_unique<control::ControlServer>(io, ControlHandlerFor(*fleet, host.conductor(), boundary),
                                                 control::ControlServerOptions{.token = options.token});
    const auto bound = control_server->Listen(spec.orchestrator().control());
    control_endpoint = "tcp://" + wire::TcpEndpointText(bound);
  } catch (const std::exception& e) {
    spdlog::critical("{}", e.what());
    return 2;
  }
  spdlog::info("control API on {}, nodes connect to {}", control_endpoint, broker_endpoint);

  // Telemetry: the buses' statistics and the fault event log on DDS (the nodes publish their own);
  // the fleet runs without it if DDS fails.
  if (options.telemetry) host.StartTelemetry(options.dds, std::chrono::seconds(1));
  // The scenario's status and verdicts (issue 29), for `canfleet top`, `canfleet watch` and any reader.
  std::unique_ptr<broker::ScenarioTelemetry> scenario_telemetry;
  if (auto* publisher = host.publisher())
    scenario_telemetry = PublishScenario(*fleet, *publisher, host.scheduler());
  const auto& topology_nodes = spec.node();
  fleet->OnFaultEvent([&](const control::FaultStatus& status, bool started) {
    broker::BrokerTelemetry* bus_telemetry = host.telemetry();
    if (bus_telemetry == nullptr) return;
    try {
      if (started) {
        broker::FaultReport report;
        report.bus = status.spec().bus();
        report.fault_id = status.fault_id();
        report.kind = std::string(control::FaultKindName(status.spec().kind()));
        // The node it is about, by its node-ID on the fault's bus (monitors show "node 5").
        for (const auto& node : topology_nodes) {
          if (node.name() != status.spec().node()) continue;
          for (int p = 0; p < node.bus_size(); ++p) {
            const int i = node.node_id_size() == 1 ? 0 : p;
            if (node.bus(p) == report.bus && i < node.node_id_size() && node.node_id(i) <= 127)
              report.target_node = static_cast<std::uint8_t>(node.node_id(i));
          }
        }
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

  // --web: `canfleet web` beside the fleet, as a child tied to this process (web/README.md).
  pid_t web_pid = 0;
  if (!options.web.empty()) {
    const auto logs = std::filesystem::path(spec.orchestrator().state_root()) / "logs";
    std::error_code ignored;
    std::filesystem::create_directories(logs, ignored);
    LaunchSpec web{.binary = std::filesystem::read_symlink("/proc/self/exe", ignored),
                   .args = {"--control", control_endpoint, "web", "--listen", options.web, "--broker",
                            broker_endpoint, "--ready-file", (logs / "web.ready").string()},
                   .log_file = logs / "web.log"};
    for (auto& arg : telemetry::DdsArguments(options.dds))
      web.args.push_back(std::move(arg));
    try {
      std::filesystem::remove(logs / "web.ready", ignored);
      web_pid = SpawnChild(web);
      spdlog::info("canfleet web on {} (pid {}; its URL: {}, log {})", options.web, web_pid,
                   (logs / "web.ready").string(), web.log_file.string());
    } catch (const std::exception& e) {
      spdlog::error("canfleet web: {}", e.what());
    }
  }

  bool stopping = false;
  auto shutdown = [&](const char* why) {
    if (stopping) return;
    stopping = true;
    spdlog::info("{}: stopping the fleet", why);
    // Driven time runs on its own while the nodes stop: nobody steps it any more.
    if (auto* conductor = host.conductor(); conductor != nullptr && conductor->Driven()) conductor->Undrive();
    if (web_pid > 0) kill(web_pid, SIGTERM);
    fleet->Stop([&] {
      spdlog::info("every node process has stopped");
      control_server->Close();
      host.Stop();
    });
  };
  fleet->OnReady([&] {
    // Driven: the fleet stops at the end of the round in which it became ready, the same
    // simulated instant on every run, and waits for its test's first step.
    if (options.driven && host.conductor() != nullptr && !host.conductor()->Driven())
      host.conductor()->Drive();
    WriteStateFile(options.ready_file, control_endpoint, broker_endpoint, "ready");
  });
  fleet->OnShutdownRequest([&] { shutdown("canfleet down"); });
  host.OnSignal(shutdown);
  fleet->Start();
  if (auto* conductor = host.conductor()) {
    spdlog::info("virtual time: {}", conductor->Speed() > 0
                                         ? "paced at " + std::to_string(conductor->Speed()) + "x real time"
                                         : std::string("as fast as the processes go"));
    if (!options.no_start) conductor->HoldUntilJoined(NodeProcesses(spec), kJoinTimeout);
    // A fleet that starts no node process is driven from time 0: its nodes (started by the test,
    // as the conformance suite does) join a fleet that stands still.
    if (options.driven && options.no_start) conductor->Drive();
  }
  io.run();
  scenario_telemetry.reset();  // before the fleet, whose hooks call it
  control_server.reset();
  fleet.reset();
  spdlog::info("stopped");
  return 0;
}

}  // namespace canfleet::fleet
