// canfleet io set NODE NAME VALUE, canfleet io get NODE [NAME] [--json]
#include <iostream>
#include <memory>

#include "tools/canfleet/cli.hpp"
#include "tools/canfleet/text_format.hpp"

namespace canfleet::cli {

namespace {

struct IoArgs {
  std::string node;
  std::string name;
  std::string value;
  bool json = false;
};

}  // namespace

void AddIoCommands(CLI::App& app, Cli& cli) {
  CLI::App* io = app.add_subcommand("io", "Set a node's simulated inputs, read its signals");
  io->require_subcommand(1);

  auto set_args = std::make_shared<IoArgs>();
  CLI::App* set = io->add_subcommand("set", "Set a simulated input (IN1.voltage_mV 2500)");
  set->add_option("NODE", set_args->node, "Node name")->required();
  set->add_option("NAME", set_args->name, "Signal name")->required();
  set->add_option("VALUE", set_args->value, "Value, as the signal takes it: 2500, true, open")->required();
  set->callback([&cli, set_args] {
    cli.action = [&cli, set_args] {
      control::Request request;
      auto* body = request.mutable_io_set();
      body->set_node(set_args->node);
      body->set_name(set_args->name);
      body->set_value(set_args->value);
      PrintDone(Call(cli.global, request), set_args->node + " " + set_args->name + " = " + set_args->value);
      return kExitOk;
    };
  });

  auto get_args = std::make_shared<IoArgs>();
  CLI::App* get = io->add_subcommand("get", "Read one signal (prints its value) or every signal (a table)");
  get->add_option("NODE", get_args->node, "Node name")->required();
  get->add_option("NAME", get_args->name, "Signal name (default: every signal)");
  get->add_flag("--json", get_args->json, "Print the IoValues message as JSON");
  get->callback([&cli, get_args] {
    cli.action = [&cli, get_args] {
      control::Request request;
      auto* body = request.mutable_io_get();
      body->set_node(get_args->node);
      body->set_name(get_args->name);
      const control::Response response = Call(cli.global, request);
      const control::IoValues& values = response.io();
      if (get_args->json) {
        PrintJson(values);
      } else if (!get_args->name.empty() && values.values_size() == 1) {
        std::cout << values.values(0).value() << '\n';  // one value alone, for scripts
      } else {
        std::cout << FormatIoValues(values);
      }
      return kExitOk;
    };
  });
}

}  // namespace canfleet::cli
