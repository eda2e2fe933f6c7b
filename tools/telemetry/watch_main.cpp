// canfleet-watch: `canfleet watch` as a program of its own (links DDS only: small, for containers next to a
// fleet).
#include <CLI/CLI.hpp>

#include <iostream>

#include "telemetry/dds.hpp"
#include "tools/telemetry/watch.hpp"

int main(int argc, char** argv) {
  CLI::App app{"Stream of fleet events (EMCY, NMT and controller changes, faults), one per line"};
  canfleet::tools::WatchOptions options;
  canfleet::tools::AddWatchOptions(app, options);
  CLI11_PARSE(app, argc, argv);
  try {
    return canfleet::tools::RunWatch(options);
  } catch (const std::exception& e) {
    std::cerr << "canfleet-watch: " << e.what() << '\n';
    return 1;
  }
}
