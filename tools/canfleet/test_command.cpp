// canfleet test FILE... (issue 21): scenario files with expectations, judged on private fleets.
#include <iostream>
#include <memory>

#include "orchestrator/fleet/fleet_time.hpp"
#include "orchestrator/fleet/run_test.hpp"
#include "telemetry/cli_options.hpp"
#include "tools/canfleet/cli.hpp"

namespace canfleet::cli {

namespace {

struct TestArgs {
  std::vector<std::string> files;
  std::string junit;
  std::string time;  ///< "" = each topology's time.mode
  std::string speed;
  std::string lookahead = "node";
  std::string capture;
  std::uint64_t seed = 0;
  std::string state_dir;
  std::string node_binary;
  std::string ready_timeout = "60s";
  std::string log_level = "info";
  bool telemetry = false;
  telemetry::DdsOptions dds;
};

}  // namespace

void AddTestCommand(CLI::App& app, Cli& cli) {
  auto args = std::make_shared<TestArgs>();
  CLI::App* test = app.add_subcommand(
      "test",
      "Run scenario files with expectations, each on its own fleet, and report a verdict per expectation");
  test->footer(
      "Prints one line per expectation as it is decided and a summary; exit 0 only if every expectation "
      "passed "
      "(1: one failed or a fleet did not start; 2: bad arguments or a refused file).");
  test->add_option("FILE", args->files, "Topology files with a scenario (protobuf text format)")
      ->required()
      ->check(CLI::ExistingFile);
  test->add_option("--junit", args->junit, "Write a JUnit XML report (one test suite per file)");
  test->add_option(
          "--time", args->time,
          "Time of the fleets: real, or virtual (lock-step, as fast as the processes go unless --speed); "
          "default: each topology's time.mode")
      ->check(CLI::IsMember({"real", "virtual"}));
  test->add_option("--speed", args->speed, "Virtual time: max, or simulated seconds per real second");
  test->add_option(
          "--lookahead", args->lookahead,
          "Virtual time at max speed: grant each node process as far as nothing it listens to can "
          "reach it (node), or all to the lookahead of the earliest (global: as before issue 34, for "
          "comparison); the captures are the same")
      ->check(CLI::IsMember({"node", "global"}))
      ->capture_default_str();
  test->add_option(
      "--capture", args->capture,
      "Capture every bus to DIR/<file>-<bus>.log (candump log; in virtual time the timestamps are "
      "simulated seconds, the same on every run)");
  CLI::Option* seed = test->add_option(
      "--seed", args->seed,
      "Seed of the random draws of faults that give none (overrides time.seed); in the report");
  test->add_option(
      "--state-dir", args->state_dir,
      "Keep each fleet's state and logs here (default: a temporary folder, kept only on failure)");
  test->add_option("--node-binary", args->node_binary,
                   "canfleet-node to start (default: beside canfleet, then PATH)");
  test->add_option("--ready-timeout", args->ready_timeout, "A fleet not ready by then did not start")
      ->check(DurationValidator())
      ->capture_default_str();
  test->add_option("--log-level", args->log_level,
                   "Level of each orchestrator log (orchestrator.log in the state dir)")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));
  test->add_flag("--telemetry", args->telemetry, "Nodes and buses publish over DDS (canfleet top can watch)");
  telemetry::AddDdsOptions(*test, args->dds, telemetry::DdsDiscovery::kMonitorsOnly);
  test->callback([&cli, args, seed] {
    cli.action = [args, seed] {
      fleet::TestOptions options;
      for (const auto& file : args->files)
        options.files.emplace_back(file);
      options.junit = args->junit;
      options.time.mode = args->time;
      options.time.global_lookahead = args->lookahead == "global";
      if (!args->speed.empty()) {
        try {
          options.time.speed = fleet::ParseSpeed(args->speed);
        } catch (const std::invalid_argument& e) {
          std::cerr << "canfleet test: " << e.what() << '\n';
          return kExitUsage;
        }
      }
      if (seed->count() > 0) options.seed = args->seed;  // also seeds the faults that give none
      options.state_dir = args->state_dir;
      options.capture = args->capture;
      options.node_binary = args->node_binary;
      options.ready_timeout = std::chrono::milliseconds(DurationMs(args->ready_timeout));
      options.log_level = args->log_level;
      options.telemetry = args->telemetry;
      options.dds = args->dds;
      return fleet::RunTests(options, std::cout);
    };
  });
}

}  // namespace canfleet::cli
