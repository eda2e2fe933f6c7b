// canfleet-top: `canfleet top` as a program of its own (links DDS only: small, for containers next to a
// fleet).
#include <CLI/CLI.hpp>

#include <iostream>

#include "telemetry/dds.hpp"
#include "tools/telemetry/top.hpp"

int main(int argc, char** argv) {
  CLI::App app{"Live table of every CANopen node of every bus on a DDS domain"};
  canfleet::tools::TopOptions options;
  canfleet::tools::AddTopOptions(app, options);
  CLI11_PARSE(app, argc, argv);
  try {
    return canfleet::tools::RunTop(options);
  } catch (const std::exception& e) {
    std::cerr << "canfleet-top: " << e.what() << '\n';
    return 1;
  }
}
