// canfleet nmt start|stop|preop|reset|reset-comm [NODE]
#include <array>
#include <memory>

#include "tools/canfleet/cli.hpp"

namespace canfleet::cli {

namespace {

struct NmtVerb {
  const char* name;
  control::NmtAction action;
  const char* help;
};

constexpr std::array<NmtVerb, 5> kVerbs{{
    {"start", control::NMT_START, "Enter operational (01h)"},
    {"stop", control::NMT_STOP, "Enter stopped (02h)"},
    {"preop", control::NMT_PREOP, "Enter pre-operational (80h)"},
    {"reset", control::NMT_RESET, "Reset the application (81h)"},
    {"reset-comm", control::NMT_RESET_COMM, "Reset communication (82h)"},
}};

}  // namespace

void AddNmtCommands(CLI::App& app, Cli& cli) {
  CLI::App* nmt = app.add_subcommand("nmt", "Send an NMT command to a node or to every node");
  nmt->require_subcommand(1);
  for (const NmtVerb& verb : kVerbs) {
    auto node = std::make_shared<std::string>();
    CLI::App* cmd = nmt->add_subcommand(verb.name, verb.help);
    cmd->add_option("NODE", *node, "Node name (default: every node, node-ID 0 on every bus)");
    cmd->callback([&cli, node, &verb] {
      cli.action = [&cli, node, &verb] {
        control::Request request;
        auto* body = request.mutable_nmt();
        body->set_action(verb.action);
        body->set_node(*node);
        PrintDone(Call(cli.global, request),
                  std::string("NMT ") + verb.name + " sent to " + (node->empty() ? "every node" : *node));
        return kExitOk;
      };
    });
  }
}

}  // namespace canfleet::cli
