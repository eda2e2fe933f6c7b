// canfleet up FILE, canfleet down, canfleet check FILE.
#include <iostream>
#include <memory>
#include <optional>
#include "bus/wire/auth_token.hpp"
#include "telemetry/cli_options.hpp"

#include "orchestrator/fleet/fleet_time.hpp"
#include "orchestrator/fleet/run_fleet.hpp"
#include "orchestrator/topology/topology_loader.hpp"
#include "tools/canfleet/cli.hpp"

namespace canfleet::cli {

namespace {

struct UpArgs {
  std::string topology;
  std::string listen;
  std::string socketcand_bind = "127.0.0.1";
  std::string node_binary;
  std::string ready_file;
  std::string log_level = "info";
  bool no_start = false;
  bool driven = false;
  std::string web;
  bool telemetry = true;
  std::string time;       ///< "" = the topology's
  std::string speed;      ///< "" = the topology's
  std::string state_dir;  ///< "" = the topology's state_root
  std::string capture_dir;
  std::optional<std::uint64_t> seed;
  telemetry::DdsOptions dds;
};

int RunUp(const GlobalOptions& global, const UpArgs& args) {
  fleet::UpOptions options;
  options.topology = args.topology;
  if (global.control_given) options.control = global.control;
  if (!args.listen.empty()) options.listen = args.listen;
  options.socketcand_bind = args.socketcand_bind;
  try {
    options.token = wire::ResolveToken().value_or("");  // --token-file sets CANFLEET_TOKEN_FILE
  } catch (const std::runtime_error& e) {
    std::cerr << "canfleet up: " << e.what() << '\n';
    return kExitUsage;
  }
  options.node_binary = args.node_binary;
  options.ready_file = args.ready_file;
  options.log_level = args.log_level;
  options.no_start = args.no_start;
  options.driven = args.driven;
  options.web = args.web;
  options.telemetry = args.telemetry;
  options.dds = args.dds;
  options.time.mode = args.time;
  if (!args.state_dir.empty()) options.state_root = args.state_dir;
  options.capture_dir = args.capture_dir;
  options.seed = args.seed;
  if (!args.speed.empty()) {
    try {
      options.time.speed = fleet::ParseSpeed(args.speed);
    } catch (const std::invalid_argument& e) {
      std::cerr << "canfleet up: " << e.what() << '\n';
      return kExitUsage;
    }
  }
  return fleet::RunFleet(options);
}

std::string Plural(int n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

int RunCheck(const std::string& file) {
  try {
    const topology::LoadedTopology loaded = topology::LoadTopology(file);
    // Warnings do not refuse the file (exit 0): it loads, but what they name cannot work.
    for (const auto& warning : loaded.warnings)
      std::cerr << warning.Message() << '\n';
    int expectations = 0;
    for (const auto& step : loaded.spec.scenario())
      expectations += step.has_expect() ? 1 : 0;
    std::cout << "ok: " << Plural(loaded.spec.bus_size(), "bus", "buses") << ", "
              << Plural(loaded.spec.node_size(), "node", "nodes");
    if (loaded.spec.scenario_size() > 0)
      std::cout << ", " << Plural(loaded.spec.scenario_size() - expectations, "action", "actions") << ", "
                << Plural(expectations, "expectation", "expectations");
    std::cout << "; offered load";
    for (std::size_t i = 0; i < loaded.loads.size(); ++i)
      std::cout << (i ? ", " : " ") << loaded.loads[i].bus << " " << loaded.loads[i].Describe();
    if (!loaded.warnings.empty())
      std::cout << "; " << Plural(static_cast<int>(loaded.warnings.size()), "warning", "warnings");
    std::cout << '\n';
    return kExitOk;
  } catch (const topology::TopologyError& e) {
    std::cerr << e.what() << '\n';
    return kExitUsage;
  }
}

}  // namespace

void AddUpCommands(CLI::App& app, Cli& cli) {
  auto args = std::make_shared<UpArgs>();
  CLI::App* up = app.add_subcommand("up", "Run the fleet of a topology file until Ctrl-C or `canfleet down`");
  up->footer("--control (or CANFLEET_CONTROL) overrides where the topology says the control API listens.");
  up->add_option("FILE", args->topology, "Topology file (protobuf text format)")
      ->required()
      ->check(CLI::ExistingFile);
  up->add_option("--listen", args->listen,
                 "Broker endpoint for nodes, overriding the topology (tcp://HOST:PORT)");
  up->add_option("--socketcand-bind", args->socketcand_bind,
                 "Address the buses' socketcand endpoints listen on (0.0.0.0 in a container)")
      ->capture_default_str();
  up->add_option("--node-binary", args->node_binary,
                 "canfleet-node to start (default: beside canfleet, then PATH)");
  up->add_option("--ready-file", args->ready_file,
                 "Written once every node booted: \"control <endpoint>\" and \"broker <endpoint>\" lines");
  up->add_option("--log-level", args->log_level, "Orchestrator log level")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));
  up->add_flag("--no-start", args->no_start, "Start the buses but no node processes");
  up->add_option(
        "--time", args->time,
        "real, or virtual: lock-step virtual time, the broker owns the clock (default: the topology's "
        "time.mode)")
      ->check(CLI::IsMember({"real", "virtual"}));
  up->add_option(
      "--speed", args->speed,
      "Virtual time: max (as fast as the processes go) or simulated seconds per real second, e.g. 10 "
      "(default: the topology's time.speed, else max)");
  up->add_flag("--driven", args->driven,
               "Virtual time: once the fleet is ready (with --no-start: from time 0) its time runs only "
               "when a client advances it (the control API's ClockAdvance; python/canfleet's fleet.run, "
               "bus waits and expectations)");
  up->add_option("--web", args->web,
                 "Also serve the fleet in a browser on [ADDR:]PORT (canfleet web; its URL in "
                 "<state_root>/logs/web.ready)");
  up->add_option("--state-dir", args->state_dir,
                 "Folder for the nodes' state and logs, instead of the topology's state_root (a private "
                 "fleet: tests, python/canfleet)");
  up->add_option("--capture-dir", args->capture_dir,
                 "Folder for captures asked for over the control API (`canfleet capture start`): a relative "
                 "--file goes there; the orchestrator writes captures only there and in the state folder "
                 "(default: <state folder>/captures)");
  up->add_option("--seed", args->seed,
                 "Seed of the random draws of faults that give none (overrides the topology's time.seed)");
  up->add_flag("!--no-telemetry", args->telemetry, "Do not publish BusStats and FaultEvents over DDS");
  telemetry::AddDdsOptions(*up, args->dds, telemetry::DdsDiscovery::kMonitorsOnly);
  up->callback([&cli, args] { cli.action = [&cli, args] { return RunUp(cli.global, *args); }; });

  CLI::App* down = app.add_subcommand("down", "Stop every node process and the orchestrator");
  down->callback([&cli] {
    cli.action = [&cli] {
      control::Request request;
      request.mutable_shutdown();
      PrintDone(Call(cli.global, request), "orchestrator stopping");
      return kExitOk;
    };
  });

  auto file = std::make_shared<std::string>();
  CLI::App* check = app.add_subcommand(
      "check", "Load and validate a topology file without starting anything; warn about what cannot work");
  check->add_option("FILE", *file, "Topology file")->required();
  check->callback([&cli, file] { cli.action = [file] { return RunCheck(*file); }; });
}

}  // namespace canfleet::cli
