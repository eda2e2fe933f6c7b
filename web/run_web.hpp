#pragma once
/// @file `canfleet web`: the fleet in a browser (web/README.md). Reads the DDS domain as `canfleet
/// top` does (any fleet on it: local, docker compose, swarm), serves the page, and forwards the
/// page's actions to the orchestrator's control API.

#include <CLI/CLI.hpp>

#include <chrono>
#include <filesystem>
#include <string>

#include "telemetry/dds.hpp"

namespace canfleet::web {

struct WebOptions {
  std::string listen = "127.0.0.1:8080";  ///< [ADDR:]PORT
  std::filesystem::path static_dir;       ///< empty: the repository's web/static
  std::string control;                    ///< control endpoint for actions; empty: read-only
  std::string broker;                     ///< broker endpoint for CANopen-Diag statistics; empty: none
  bool read_only = false;
  std::string token_file;  ///< --token-file; else CANFLEET_TOKEN_FILE / CANFLEET_TOKEN
  int retention_s = 600;
  int update_ms = 200;
  std::filesystem::path ready_file;  ///< written once serving: "url <url>" and "token <token>"
  telemetry::DdsOptions dds;
};

/// Adds the options of `canfleet web` to `app` (the DDS options too).
void AddWebOptions(CLI::App& app, WebOptions& options);
/// Serves until SIGINT/SIGTERM. 0, or 2 when it cannot listen (the message says why).
int RunWeb(const WebOptions& options);
/// "ADDR:PORT" or "PORT" → (address, port). Throws std::invalid_argument.
std::pair<std::string, std::uint16_t> ParseListen(const std::string& text);
/// Where the page's files are: `given`, else <prefix>/share/canfleet/web beside an installed binary
/// (the docker image), else the repository's web/static this binary was built from.
std::filesystem::path StaticDir(const std::filesystem::path& given);

}  // namespace canfleet::web
