// canfleet-node: one emulated CANopen device as its own process. Only wiring lives here:
// command line → device → ports → DeviceNode → event loop.
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <unistd.h>
#include <CLI/CLI.hpp>
#include <asio/io_context.hpp>
#include <asio/post.hpp>
#include <asio/signal_set.hpp>
#include <iostream>
#include <memory>
#include <optional>

#include "bus/broker_client/broker_client_port.hpp"
#include "bus/socketcan/socketcan_port.hpp"
#include "bus/wire/auth_token.hpp"
#include "clock/asio_scheduler.hpp"
#include "clock/granted_scheduler.hpp"
#include "node/canopen/lss/lss_protocol.hpp"
#include "node/canopen/storage/atomic_file.hpp"
#include "node/devices/device_node.hpp"
#include "node/devices/registry.hpp"
#include "node/process/bit_rate_commissioning.hpp"
#include "node/process/node_options.hpp"
#include "node/process/node_telemetry_wiring.hpp"
#include "node/process/release_memory.hpp"
#include "node/process/remote_io.hpp"
#include "node/process/stdin_control.hpp"

namespace {

using namespace canfleet;

constexpr const char* kVersion = "canfleet-node 0.1.0";

std::unique_ptr<BusPort> MakePort(asio::io_context& io, const node::BusSpec& spec,
                                  const node::NodeOptions& options, std::uint8_t node_id,
                                  std::shared_ptr<spdlog::logger> log, VirtualTimeClient* virtual_time,
                                  std::size_t index, std::function<void()> on_first_connect) {
  if (spec.socketcan) {
    if (virtual_time != nullptr)
      throw std::invalid_argument("--time virtual: port " + std::to_string(index + 1) +
                                  " is SocketCAN interface " + spec.bus +
                                  ", which lives in real time; a node in virtual time needs broker buses");
    auto port = std::make_unique<SocketCanPort>(io, spec.bus);
    port->OnError([log](std::error_code ec) { log->error("socketcan: {}", ec.message()); });
    asio::post(io, on_first_connect);
    return port;
  }
  BrokerClientOptions client;
  client.endpoint = spec.endpoint;
  client.bus = spec.bus;
  client.node_name = options.name;
  client.node_id = node::BrokerHelloNodeId(node_id);
  client.token = options.token;
  client.virtual_time = virtual_time;
  client.virtual_time_index = index;
  auto port = std::make_unique<BrokerClientPort>(io, client);
  port->OnConnection(
      [log, started = false, on_first_connect](bool connected, const std::string& detail) mutable {
        if (connected) {
          log->info("connected to the broker: {}", detail);
          // Power-on happens when the cable is first plugged in: the boot-up frame must reach the bus.
          if (!started) {
            started = true;
            on_first_connect();
          }
        } else {
          log->warn("broker connection: {}", detail);
        }
      });
  return port;
}

int Run(const node::NodeOptions& options, const node::TelemetrySettings& telemetry_settings) {
  // Logs on stderr: stdout carries --stdin-control replies, which scripts read line by line.
  auto log = spdlog::stderr_color_mt(options.name);
  log->set_level(spdlog::level::from_str(options.log_level));
  spdlog::set_default_logger(log);

  auto device = devices::MakeDevice({options.device, options.eds});
  const std::size_t port_count = device->PortCount();
  if (options.buses.size() != port_count) {
    throw std::invalid_argument("--bus: device '" + std::string(device->Name()) + "' has " +
                                std::to_string(port_count) + " CAN port(s) but " +
                                std::to_string(options.buses.size()) + " --bus option(s) were given");
  }
  if (options.node_ids.size() != 1 && options.node_ids.size() != port_count) {
    throw std::invalid_argument("--node-id: give one node-ID, or one per CAN port (" +
                                std::to_string(port_count) + ")");
  }

  asio::io_context io;
  // Real time, or time granted by the broker (--time virtual): the node's code is the same.
  std::unique_ptr<Scheduler> scheduler_owner;
  std::optional<VirtualTimeClient> virtual_time;
  if (options.virtual_time) {
    auto granted = std::make_unique<GrantedScheduler>();
    virtual_time.emplace(*granted, options.name + "#" + std::to_string(::getpid()), port_count);
    scheduler_owner = std::move(granted);
  } else {
    scheduler_owner = std::make_unique<AsioScheduler>(io);
  }
  Scheduler& scheduler = *scheduler_owner;
  devices::NodeSettings settings;
  settings.state_dir = options.state_dir;
  settings.serial_number = options.serial_number;
  settings.hooks.on_state_changed = [log](canopen::NmtState s) {
    log->info("NMT state: {}", canopen::ToString(s));
  };
  settings.hooks.on_comm_error = [log](const canopen::CommError& e, bool active) {
    log->warn("communication error {} (detail {}) {}", static_cast<int>(e.kind), e.detail,
              active ? "raised" : "cleared");
  };
  settings.hooks.on_storage_issue = [log](const std::string& text) {
    log->warn("stored parameters: {}", text);
  };
  devices::DeviceNode::BitRateReport on_bit_rate = [log, told = std::vector<bool>(port_count, false)](
                                                       std::size_t p, std::uint32_t kbit,
                                                       bool applied) mutable {
    if (applied) {
      log->info("CAN{}: bit rate now {} kbit/s", p + 1, kbit);
    } else if (!told[p]) {
      told[p] = true;  // once: the interface's rate does not change with the node's settings
      log->warn(
          "CAN{}: bit rate {} kbit/s not applied: a SocketCAN interface runs at the rate it was "
          "given (ip link set IFACE type can bitrate ...)",
          p + 1, kbit);
    }
  };
  auto telemetry = node::StartNodeTelemetry(telemetry_settings, settings, *log);  // DDS (issue 7)

  std::unique_ptr<devices::DeviceNode> node;
  std::size_t connected_ports = 0;
  std::vector<std::unique_ptr<BusPort>> ports;
  auto start_when_all_connected = [&] {
    if (++connected_ports == port_count) {
      for (std::size_t p = 0; p < port_count; ++p) {
        const auto log_line = [&log](const std::string& line) { log->info("{}", line); };
        if (options.factory_bit_rate)
          node::KeepFactoryBitRate(*node, p, *ports[p], log_line);
        else
          node::CommissionBitRate(*node, p, *ports[p], log_line);
      }
      node->Start();
      log->info("powered on");
      node::ReleaseFreedHeap();  // what loading the stored parameters freed
    }
  };
  std::vector<BusPort*> raw_ports;
  // A variant left unconfigured boots as it leaves the factory (its manual's node-ID and bit rate);
  // at the first connection a port whose rate nobody configured is commissioned for its bus
  // (node/process/bit_rate_commissioning.hpp).
  const devices::DeviceInfo* variant = devices::FindDevice(options.device);
  const std::uint8_t bit_timing =
      variant ? devices::BitTimingIndexOf(variant->factory_bit_rate_kbit).value_or(4) : std::uint8_t{4};
  for (std::size_t p = 0; p < port_count; ++p) {
    auto id = options.node_ids.size() == 1 ? options.node_ids[0] : options.node_ids[p];
    settings.ports.push_back({id, bit_timing});
    ports.push_back(MakePort(io, options.buses[p], options, id, log, virtual_time ? &*virtual_time : nullptr,
                             p, start_when_all_connected));
    raw_ports.push_back(ports.back().get());
  }
  node = std::make_unique<devices::DeviceNode>(std::move(device), scheduler, raw_ports, settings);
  node->OnBitRate(std::move(on_bit_rate));
  // A bit rate stored by LSS (CiA 305 store configuration) is the controller's from power-on: the
  // Hello states it. SocketCAN runs at its interface's rate, whatever the node's settings say.
  for (std::size_t p = 0; p < port_count; ++p) {
    if (options.buses[p].socketcan) {
      log->info("CAN{}: bit rate: the SocketCAN interface's ({} is not applied to it)", p + 1,
                "LSS activate bit timing or a bit-rate object");
    } else if (node->stack(p).BitTimingStored()) {
      if (auto kbit = canopen::BitRateKbit(node->stack(p).BitTimingIndex()))
        ports[p]->SetBitRate(*kbit * 1000);
    }
  }
  if (telemetry) telemetry->Attach(*node, scheduler, node::BusNames(options), options.name);
  // Remote I/O: the orchestrator sets and reads the simulated I/O over the broker connection.
  for (std::size_t p = 0; p < port_count; ++p) {
    auto* client = dynamic_cast<BrokerClientPort*>(ports[p].get());
    if (client == nullptr) continue;
    client->OnNodeRequest([&node, &log](const wire::NodeRequest& r) {
      wire::NodeReply reply = node::AnswerNodeRequest(node->io(), r);
      if (!reply.notice().empty()) log->warn("simulated I/O: {}", reply.notice());
      return reply;
    });
    // The broker wakes the node only for frames its stack listens to (an acceptance filter).
    client->OnAcceptance([&node, p] { return node->ListenedIds(p); });
    client->OnPassive([&node, p] { return node->PassiveIds(p); });
  }
  for (const auto& assignment : options.io) {
    auto eq = assignment.find('=');
    if (eq == std::string::npos) throw std::invalid_argument("--io " + assignment + ": expected NAME=VALUE");
    auto status = node->io().SetText(assignment.substr(0, eq), assignment.substr(eq + 1));
    if (!status.ok()) throw std::invalid_argument("--io " + assignment + ": " + status.error);
    if (!status.notice.empty()) log->warn("--io {}: {}", assignment, status.notice);
  }

  std::unique_ptr<node::StdinControl> control;
  if (options.stdin_control) {
    control = std::make_unique<node::StdinControl>(io, *node);
    control->Start();
  }
  asio::signal_set signals(io, SIGINT, SIGTERM);
  signals.async_wait([&](const asio::error_code& ec, int signal) {
    if (!ec) log->info("signal {}: shutting down", signal);
    io.stop();
  });
  node::ReleaseFreedHeap();  // what parsing the EDS and building the dictionaries freed
  log->info("{} node-ID {} on {} port(s); waiting for the bus", node->device().Name(),
            static_cast<int>(options.node_ids[0]), port_count);
  io.run();
  // Destroy the node (its timers and hooks) before the ports and the scheduler it uses.
  control.reset();
  telemetry.reset();  // disposes the node's DDS instances: monitors see it leave
  node.reset();
  return 0;
}

// --write-eds: the EDS a user loads into their own master, exactly the one the node runs on.
int WriteEds(const std::string& device, const std::string& path) {
  const devices::DeviceInfo* variant = devices::FindDevice(device);
  if (variant == nullptr) {
    throw std::invalid_argument("--write-eds needs --device NAME (known: " + devices::KnownDeviceNames() +
                                ")");
  }
  const std::string text = variant->eds().Text();
  if (path == "-") {
    std::cout << text;
    return 0;
  }
  const auto bytes = std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size());
  if (const std::error_code ec = canopen::WriteFileAtomically(path, bytes))
    throw std::invalid_argument("--write-eds " + path + ": " + ec.message());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  canfleet::node::UseOneMallocArena();  // first: before DDS or anything else starts a thread
  CLI::App app{"canfleet-node: one emulated CANopen device on a virtual or real CAN bus"};
  canfleet::node::NodeOptions options;
  std::vector<std::string> buses;
  std::vector<int> node_ids;
  std::uint32_t serial = 0;
  bool list = false, version = false;
  std::string write_eds, token_file;
  app.add_option("--device", options.device, "device variant (see --list-devices)");
  app.add_option("--eds", options.eds, "EDS file: a generic CiA 301 slave, or replaces the variant's EDS")
      ->check(CLI::ExistingFile);
  app.add_option("--node-id", node_ids,
                 "node-ID 1..127, or 255 for an unconfigured LSS slave; one per port (default: the variant's "
                 "factory node-ID, see --list-devices)")
      ->check(CLI::Range(1, 255));
  app.add_option("--bus", buses, "BUS@tcp://HOST:PORT, BUS@unix:///PATH or socketcan:IFACE; one per port");
  app.add_option(
      "--token-file", token_file,
      "file holding the fleet's token, for a broker beyond loopback (default: CANFLEET_TOKEN_FILE, "
      "else CANFLEET_TOKEN)");
  app.add_option("--state-dir", options.state_dir, "folder for stored parameters (1010h) and LSS settings");
  auto* serial_opt = app.add_option("--serial", serial, "serial number (1018h sub 4)");
  app.add_option("--name", options.name, "name in logs and on the broker (default DEVICE@ID)");
  app.add_option("--io", options.io, "initial simulated input NAME=VALUE (repeatable)");
  app.add_flag("--factory-bit-rate", options.factory_bit_rate,
               "a port with no bit rate configured (LSS, 5B50h) runs at the variant's factory rate, as a "
               "factory-new device plugged into the bus (default: commissioned for its bus's rate)");
  std::string time_mode = "real";
  app.add_option("--time", time_mode,
                 "real: the node keeps real time; virtual: it runs on the time its broker grants (a bus in "
                 "virtual time, canfleet up --time virtual)")
      ->check(CLI::IsMember({"real", "virtual"}));
  app.add_flag("--stdin-control", options.stdin_control,
               "accept set/get/list/nmt commands on standard input");
  app.add_option("--log-level", options.log_level, "trace, debug, info, warn, error")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));
  app.add_flag("--list-devices", list, "list the device variants and exit");
  app.add_option("--write-eds", write_eds,
                 "write the --device variant's EDS to FILE (- for stdout) and exit");
  app.add_flag("--version", version, "print the version and exit");
  canfleet::node::TelemetrySettings telemetry;
  canfleet::node::AddTelemetryOptions(app, telemetry);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version are "errors" with code 0; every real argument error exits 2.
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }

  if (version) {
    std::cout << kVersion << "\n";
    return 0;
  }
  if (list) {
    std::cout << canfleet::devices::ListDevices();
    return 0;
  }
  try {
    if (!write_eds.empty()) return WriteEds(options.device, write_eds);
    if (options.device.empty() && options.eds.empty()) throw std::invalid_argument("give --device or --eds");
    if (buses.empty()) throw std::invalid_argument("give at least one --bus");
    if (node_ids.empty()) {
      const auto* variant = canfleet::devices::FindDevice(options.device);
      if (variant == nullptr)
        throw std::invalid_argument("give --node-id (a generic node has no factory node-ID)");
      node_ids.push_back(variant->factory_node_id);
    }
    for (const auto& b : buses)
      options.buses.push_back(canfleet::node::ParseBusSpec(b));
    for (int id : node_ids) {
      if (id > 127 && id != 255)
        throw std::invalid_argument("--node-id " + std::to_string(id) + ": 1..127 or 255");
      options.node_ids.push_back(static_cast<std::uint8_t>(id));
    }
    if (*serial_opt) options.serial_number = serial;
    options.token = canfleet::wire::ResolveToken(token_file).value_or("");
    options.virtual_time = time_mode == "virtual";
    if (options.virtual_time && options.stdin_control)
      throw std::invalid_argument(
          "--stdin-control works in real time only (use canfleet io in virtual time)");
    if (options.name.empty()) {
      options.name = (options.device.empty() ? options.eds.stem().string() : options.device) + "@" +
                     std::to_string(node_ids[0]);
    }
    return Run(options, telemetry);
  } catch (const std::exception& e) {
    std::cerr << "canfleet-node: " << e.what() << "\n";
    return 2;
  }
}
