// canfleet: the command line of the fleet (tools/canfleet/README.md). `up` runs the orchestrator;
// every other command talks to a running one over the control API. One file per command group.
#include <cstdlib>
#include <iostream>

#include "orchestrator/control/control_protocol.hpp"
#include "tools/canfleet/cli.hpp"

int main(int argc, char** argv) {
  using namespace canfleet::cli;
  Cli cli;
  CLI::App app{"canfleet: run a fleet of simulated CANopen devices and drive it"};
  app.set_version_flag("--version", CANFLEET_VERSION);
  app.require_subcommand(1);
  app.fallthrough();  // global options may follow the subcommand
  cli.global.control = std::string(canfleet::control::kDefaultControlEndpoint);
  CLI::Option* control =
      app.add_option("--control", cli.global.control, "The orchestrator's control API (tcp://HOST:PORT)")
          ->envname("CANFLEET_CONTROL")
          ->capture_default_str();
  std::string token_file;
  app.add_option(
         "--token-file", token_file,
         "File holding the fleet's token: sent to an orchestrator beyond loopback (clients), required "
         "of clients when listening beyond loopback (up). Default: CANFLEET_TOKEN_FILE, else "
         "CANFLEET_TOKEN")
      ->check(CLI::ExistingFile);
  std::string timeout = "30s";
  app.add_option("--timeout", timeout, "How long to wait for the orchestrator's answer")
      ->check(DurationValidator())
      ->capture_default_str();

  AddUpCommands(app, cli);
  AddTestCommand(app, cli);
  AddStatusCommand(app, cli);
  AddFaultCommands(app, cli);
  AddIoCommands(app, cli);
  AddSdoCommands(app, cli);
  AddNmtCommands(app, cli);
  AddDumpCommand(app, cli);
  AddCaptureCommands(app, cli);
  AddTelemetryCommands(app, cli);

  try {
    app.parse(argc, argv);
    cli.global.control_given = control->count() > 0;
    cli.global.timeout = std::chrono::milliseconds(DurationMs(timeout));
    // One place for every client and server in this process (and the processes it starts).
    if (!token_file.empty()) ::setenv("CANFLEET_TOKEN_FILE", token_file.c_str(), 1);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  try {
    return cli.action ? cli.action() : kExitUsage;
  } catch (const UsageError& e) {
    std::cerr << "canfleet: " << e.what() << '\n';
    return kExitUsage;
  } catch (const std::exception& e) {
    std::cerr << "canfleet: " << e.what() << '\n';
    return kExitFailed;
  }
}
