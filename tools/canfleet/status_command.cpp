// canfleet status [--json]
#include <iostream>
#include <memory>

#include "tools/canfleet/cli.hpp"
#include "tools/canfleet/text_format.hpp"

namespace canfleet::cli {

void AddStatusCommand(CLI::App& app, Cli& cli) {
  auto json = std::make_shared<bool>(false);
  CLI::App* status =
      app.add_subcommand("status", "Buses, nodes (process, NMT, controller, TEC/REC) and faults");
  status->add_flag("--json", *json, "Print the Status message as JSON");
  status->callback([&cli, json] {
    cli.action = [&cli, json] {
      control::Request request;
      request.mutable_status();
      const control::Response response = Call(cli.global, request);
      if (*json)
        PrintJson(response.status());
      else
        std::cout << FormatStatus(response.status());
      return kExitOk;
    };
  });
}

}  // namespace canfleet::cli
