// canfleet top / canfleet watch / canfleet web: the fleet as DDS telemetry shows it (tools/telemetry/).
// Unlike every other command they do not use the control API: they read the DDS domain, so they work against
// a fleet started by anyone (a docker compose fleet, another user's `canfleet up`).
#include <memory>

#include "tools/canfleet/cli.hpp"
#include "tools/telemetry/top.hpp"
#include "tools/telemetry/watch.hpp"
#include "web/run_web.hpp"

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

  auto web_options = std::make_shared<web::WebOptions>();
  CLI::App* web = app.add_subcommand(
      "web", "The fleet in a browser: live overview, bus statistics, timeline, plots, fault controls");
  web->footer("Data from the DDS domain (as top); actions go to the control API (--control).");
  web::AddWebOptions(*web, *web_options);
  web->callback([&cli, web_options] {
    cli.action = [&cli, web_options] {
      web_options->control = cli.global.control;
      return web::RunWeb(*web_options);
    };
  });
}

}  // namespace canfleet::cli
