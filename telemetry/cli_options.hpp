#pragma once
/// @file The DDS options every canfleet program takes (CLI11), with environment fallbacks.

#include <CLI/CLI.hpp>

#include "telemetry/dds.hpp"

namespace canfleet::telemetry {

/// Adds --dds-domain (env CANFLEET_DDS_DOMAIN) and --dds-config (env CANFLEET_DDS_CONFIG).
inline void AddDdsOptions(CLI::App& app, DdsOptions& options) {
  app.add_option("--dds-domain", options.domain_id, "DDS domain id of the fleet's telemetry")
      ->envname("CANFLEET_DDS_DOMAIN")
      ->capture_default_str();
  app.add_option("--dds-config", options.config_file,
                 "Cyclone DDS XML configuration (telemetry/cyclonedds-loopback.xml for one host, "
                 "cyclonedds-default.xml in containers); default: $CYCLONEDDS_URI or Cyclone's defaults")
      ->envname("CANFLEET_DDS_CONFIG")
      ->check(CLI::ExistingFile);
}

}  // namespace canfleet::telemetry
