// canfleet top / canfleet watch: the fleet as DDS telemetry shows it (tools/telemetry/). Unlike every
// other command they do not use the control API: they read the DDS domain, so they work against a
// fleet started by anyone (a docker compose fleet, another user's `canfleet up`).
#include <memory>

#include "tools/canfleet/cli.hpp"
#include "tools/telemetry/top.hpp"
#include "tools/telemetry/watch.hpp"

namespace canfleet::cli {

void AddTelemetryCommands(CLI::App& app, Cli& cli) {
  // The options live as long as the App: CLI11 writes into them while parsing.
  auto top_options = std::make_shared<tools::TopOptions>();
  CLI::App* top = app.add_subcommand("top", "Live table of every node of every bus on the DDS domain");
  tools::AddTopOptions(*top, *top_options);
  top->callback([&cli, top_options] { cli.action = [top_options] { return tools::RunTop(*top_options); }; });

  auto watch_options = std::make_shared<tools::WatchOptions>();
  CLI::App* watch = app.add_subcommand(
      "watch", "Stream of fleet events (EMCY, NMT and controller changes, faults) from DDS");
  tools::AddWatchOptions(*watch, *watch_options);
  watch->callback(
      [&cli, watch_options] { cli.action = [watch_options] { return tools::RunWatch(*watch_options); }; });
}

}  // namespace canfleet::cli
