#pragma once
/// @file The DDS options every canfleet program takes (CLI11), with environment fallbacks.

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "telemetry/dds.hpp"

namespace canfleet::telemetry {

/// Adds --dds-domain (env CANFLEET_DDS_DOMAIN) and --dds-config (env CANFLEET_DDS_CONFIG). A
/// program that only writes passes DdsDiscovery::kMonitorsOnly (dds.hpp says why); it also gets
/// --dds-discover-all (env CANFLEET_DDS_DISCOVER_ALL) to go back to Cyclone's full discovery.
inline void AddDdsOptions(CLI::App& app, DdsOptions& options, DdsDiscovery discovery = DdsDiscovery::kAll) {
  options.discovery = discovery;
  if (discovery == DdsDiscovery::kMonitorsOnly) {
    app.add_flag_callback(
           "--dds-discover-all", [&options] { options.discovery = DdsDiscovery::kAll; },
           "discover every DDS participant, as Cyclone does by default (otherwise this program, which "
           "only writes telemetry, announces itself to monitors and meets no other writer)")
        ->envname("CANFLEET_DDS_DISCOVER_ALL");
  }
  app.add_option("--dds-domain", options.domain_id, "DDS domain id of the fleet's telemetry")
      ->envname("CANFLEET_DDS_DOMAIN")
      ->capture_default_str();
  app.add_option("--dds-config", options.config_file,
                 "Cyclone DDS XML configuration (telemetry/cyclonedds-loopback.xml for one host, "
                 "cyclonedds-default.xml in containers and across hosts); default: $CYCLONEDDS_URI, else the "
                 "loopback configuration built in (every canfleet program on this host meets the others)")
      ->envname("CANFLEET_DDS_CONFIG")
      ->check(CLI::ExistingFile);
}

/// `options` as the command-line arguments AddDdsOptions reads, for a child program (canfleet up
/// passes them to its nodes). A child that only writes decides its discovery itself unless
/// `options` asked for full discovery.
inline std::vector<std::string> DdsArguments(const DdsOptions& options) {
  std::vector<std::string> args = {"--dds-domain", std::to_string(options.domain_id)};
  if (!options.config_file.empty()) args.insert(args.end(), {"--dds-config", options.config_file});
  if (options.discovery == DdsDiscovery::kAll) args.push_back("--dds-discover-all");
  return args;
}

}  // namespace canfleet::telemetry
