// canfleet-broker: serves virtual CAN buses to node processes over TCP and Unix-domain sockets.
// main only reads its command line: the broker, its scheduler, the transport and the telemetry
// (BusStats of every bus over DDS) are wired by host::BrokerHost, as for `canfleet up`.
//
//   canfleet-broker --bus can0:500k --bus can1:1M:unpaced
//                   --listen tcp://127.0.0.1:29600 --listen unix:///tmp/canfleet.sock
//                   [--dds-config telemetry/cyclonedds-loopback.xml] [--no-telemetry]
#include <google/protobuf/stubs/logging.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <asio/io_context.hpp>
#include <charconv>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "bus/wire/auth_token.hpp"
#include "bus/wire/endpoint.hpp"
#include "orchestrator/host/broker_host.hpp"
#include "telemetry/cli_options.hpp"

namespace {

using canfleet::broker::BusConfig;

/// "500000", "500k", "1M" -> bit/s.
std::uint32_t ParseBitrate(std::string_view text, std::string_view spec) {
  std::uint64_t multiplier = 1;
  if (!text.empty() && (text.back() == 'k' || text.back() == 'K')) multiplier = 1000;
  if (!text.empty() && text.back() == 'M') multiplier = 1'000'000;
  if (multiplier != 1) text.remove_suffix(1);
  std::uint64_t value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size())
    throw std::invalid_argument("--bus " + std::string(spec) + ": bitrate \"" + std::string(text) +
                                "\" is not a number (e.g. 500000, 500k, 1M)");
  return static_cast<std::uint32_t>(std::min<std::uint64_t>(value * multiplier, UINT32_MAX));
}

/// NAME[:BITRATE][:unpaced|:paced]
BusConfig ParseBus(const std::string& spec) {
  BusConfig config;
  std::size_t start = 0;
  bool first = true;
  while (start <= spec.size()) {
    const std::size_t colon = std::min(spec.find(':', start), spec.size());
    const std::string_view part(spec.data() + start, colon - start);
    if (first) {
      config.name = std::string(part);
      first = false;
    } else if (part == "unpaced") {
      config.paced = false;
    } else if (part == "paced") {
      config.paced = true;
    } else {
      config.bitrate = ParseBitrate(part, spec);
    }
    start = colon + 1;
  }
  return config;  // Broker::AddBus validates the name and the bitrate range
}

void WriteReadyFile(const std::string& path, const std::vector<canfleet::wire::Endpoint>& endpoints) {
  // Written then renamed, so a reader never sees half a file.
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    for (const auto& ep : endpoints)
      out << ep.ToString() << '\n';
    if (!out) throw std::runtime_error("cannot write " + tmp);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0)
    throw std::runtime_error("cannot rename " + tmp + " to " + path);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"canfleet-broker: virtual CAN buses for canfleet node processes"};
  std::vector<std::string> bus_specs;
  std::vector<std::string> listens;
  std::string log_level = "info";
  std::string ready_file, token_file;
  app.add_option("--token-file", token_file,
                 "File holding the fleet's token, required of every client when listening beyond loopback "
                 "(default: CANFLEET_TOKEN_FILE, else CANFLEET_TOKEN)");
  app.add_option("--bus", bus_specs,
                 "A bus: NAME[:BITRATE][:unpaced], e.g. can0, can0:250k, can1:1M:unpaced (repeatable; "
                 "default can0:500k)");
  app.add_option("--listen", listens,
                 "Where nodes connect: tcp://HOST:PORT or unix:///PATH (repeatable; default "
                 "tcp://127.0.0.1:29600). Only loopback unless another address is given here; port 0 "
                 "picks a free port");
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error, critical or off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));
  app.add_option("--ready-file", ready_file,
                 "Once listening, write the bound endpoints there, one per line (for scripts and tests)");
  bool telemetry_enabled = true;
  double telemetry_period = 1.0;
  canfleet::telemetry::DdsOptions dds;
  app.add_flag("!--no-telemetry", telemetry_enabled, "Do not publish BusStats over DDS");
  app.add_option("--telemetry-period", telemetry_period,
                 "How often BusStats are sampled and republished, seconds")
      ->check(CLI::Range(0.05, 3600.0))
      ->capture_default_str();
  std::string time_mode = "real";
  std::string speed = "max";
  std::size_t wait_nodes = 0;
  app.add_option("--time", time_mode,
                 "real, or virtual: lock-step virtual time, the broker owns the clock and nodes join with "
                 "canfleet-node --time virtual (orchestrator/broker/README.md, \"Virtual time\")")
      ->check(CLI::IsMember({"real", "virtual"}))
      ->capture_default_str();
  app.add_option("--speed", speed, "Virtual time: max, or simulated seconds per real second (e.g. 10)")
      ->capture_default_str();
  app.add_option("--wait-nodes", wait_nodes,
                 "Virtual time: time starts once this many node processes have joined (or after 60 s)");
  canfleet::telemetry::AddDdsOptions(app, dds, canfleet::telemetry::DdsDiscovery::kMonitorsOnly);
  CLI11_PARSE(app, argc, argv);
  canfleet::host::HostTime time;
  time.virtual_time = time_mode == "virtual";
  try {
    time.conductor.speed = canfleet::host::ParseSpeed(speed);
  } catch (const std::exception& e) {
    std::cerr << "canfleet-broker: " << e.what() << "\n";
    return 2;
  }

  spdlog::set_default_logger(spdlog::stderr_color_mt("canfleet-broker"));
  spdlog::set_level(spdlog::level::from_str(log_level));
  // Protobuf reports what it rejects (e.g. invalid UTF-8 in a Hello) on stderr by itself; the
  // session already logs why it closes, so keep protobuf's own words for debugging.
  google::protobuf::SetLogHandler([](google::protobuf::LogLevel, const char*, int,
                                     const std::string& message) { spdlog::debug("protobuf: {}", message); });

  if (bus_specs.empty()) bus_specs.push_back("can0:500k");
  if (listens.empty())
    listens.push_back("tcp://127.0.0.1:" + std::to_string(canfleet::wire::kDefaultBrokerPort));

  asio::io_context io(1);
  canfleet::host::BrokerHost host(io, {}, time);
  if (auto* conductor = host.conductor()) {
    spdlog::info("virtual time ({}): nodes must join with --time virtual",
                 time.conductor.speed > 0 ? "paced at " + speed + "x" : std::string("as fast as possible"));
    conductor->HoldUntilJoined(wait_nodes, canfleet::host::kJoinTimeout);
  }
  try {
    for (const auto& spec : bus_specs)
      host.AddBus(ParseBus(spec));
    host.server().SetToken(canfleet::wire::ResolveToken(token_file).value_or(""));
    for (const auto& text : listens)
      host.Listen(canfleet::wire::Endpoint::Parse(text));
    if (telemetry_enabled)
      host.StartTelemetry(dds, std::chrono::milliseconds(static_cast<long>(telemetry_period * 1000)));
    if (!ready_file.empty()) WriteReadyFile(ready_file, host.Endpoints());
  } catch (const std::exception& e) {
    spdlog::critical("{}", e.what());
    return 2;
  }

  host.OnSignal([&](const char* signal) {
    spdlog::info("{}: shutting down", signal);
    host.Stop();
  });
  io.run();
  spdlog::info("stopped");
  return 0;
}
