// The limit of virtual time for a fleet (issue 34, item 3): the same nodes, buses and configuration
// as `canfleet test` runs in separate processes, but every node in this one process on one
// simulated scheduler, attached to the broker in-process: no sockets, no grants, no rounds. What it
// takes is the work itself (the nodes' timers and frames, the bus model); the ratio of a
// multi-process run to it does not move with the machine as a wall time does.
//
//   canfleet-vt-limit TOPOLOGY [SIMULATED_SECONDS]   (default: the topology's longest window)
//
// A benchmark tool, not a product mode: the nodes are configured as the fleet configures them (the
// same writes, by SDO over the bus, then NMT start), but there are no telemetry, no control API, no
// scenario judge and no faults.
#include <spdlog/spdlog.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "clock/granted_scheduler.hpp"
#include "node/devices/device_node.hpp"
#include "node/devices/registry.hpp"
#include "orchestrator/broker/broker.hpp"
#include "orchestrator/fleet/master_port.hpp"
#include "orchestrator/fleet/sdo_queue.hpp"
#include "orchestrator/topology/configuration_plan.hpp"
#include "orchestrator/topology/topology_loader.hpp"

namespace {

using namespace canfleet;

/// One node of the topology, in this process.
struct InProcessNode {
  std::string name;
  std::vector<std::unique_ptr<fleet::MasterPort>> ports;  ///< a plain broker port per CAN port
  std::unique_ptr<devices::DeviceNode> node;
};

std::chrono::milliseconds LongestWindow(const topology::Topology& spec) {
  std::chrono::milliseconds longest{60'000};
  for (const auto& step : spec.scenario())
    if (step.has_expect())
      longest = std::max(longest, std::chrono::milliseconds(step.at_ms() + step.expect().within_ms()));
  return longest;
}

int Run(const std::filesystem::path& file, std::optional<double> seconds) {
  const topology::LoadedTopology loaded = topology::LoadTopology(file);
  const topology::Topology& spec = loaded.spec;
  GrantedScheduler scheduler;
  broker::Broker broker(scheduler);
  for (const auto& bus : spec.bus())
    broker.AddBus({.name = bus.name(), .bitrate = bus.bitrate(), .paced = !bus.unpaced()});

  const auto state =
      std::filesystem::temp_directory_path() / ("canfleet-vt-limit-" + std::to_string(::getpid()));
  std::map<std::pair<std::string, std::string>, std::uint8_t> ids;  // (node, bus) -> node-ID
  for (const auto& n : spec.node())
    for (int p = 0; p < n.bus_size(); ++p)
      ids[{n.name(), n.bus(p)}] = static_cast<std::uint8_t>(n.node_id(n.node_id_size() == 1 ? 0 : p));

  std::vector<InProcessNode> nodes;
  for (const auto& n : spec.node()) {
    InProcessNode& in = nodes.emplace_back();
    in.name = n.name();
    devices::NodeSettings settings;
    settings.state_dir = state / n.name();
    std::vector<BusPort*> raw;
    for (int p = 0; p < n.bus_size(); ++p) {
      in.ports.push_back(std::make_unique<fleet::MasterPort>(broker, n.bus(p)));
      raw.push_back(in.ports.back().get());
      settings.ports.push_back({ids[{n.name(), n.bus(p)}], 4});
    }
    in.node = std::make_unique<devices::DeviceNode>(devices::MakeDevice({n.device(), n.eds()}), scheduler,
                                                    raw, settings);
  }
  // The fleet's master: its SDO client writes each node's configuration after boot-up, then NMT start.
  std::map<std::string, std::unique_ptr<fleet::MasterPort>> masters;
  std::map<std::string, std::unique_ptr<fleet::SdoQueue>> sdo;
  for (const auto& bus : spec.bus()) {
    masters[bus.name()] = std::make_unique<fleet::MasterPort>(broker, bus.name());
    sdo[bus.name()] = std::make_unique<fleet::SdoQueue>(*masters[bus.name()], scheduler);
  }
  for (auto& in : nodes)
    in.node->Start();
  std::size_t writes = 0;
  for (const auto& n : spec.node()) {
    std::vector<std::string> buses(n.bus().begin(), n.bus().end());
    std::vector<std::uint8_t> node_ids;
    for (const auto& b : buses)
      node_ids.push_back(ids[{n.name(), b}]);
    for (std::size_t p = 0; p < buses.size(); ++p) {
      const auto plan = topology::PlanConfiguration(
          n, buses, node_ids, p, [&](const std::string& other, const std::string& bus) {
            const auto it = ids.find({other, bus});
            return it == ids.end() ? std::nullopt : std::optional(it->second);
          });
      fleet::SdoQueue& queue = *sdo[buses[p]];
      const std::uint8_t id = node_ids[p];
      for (std::size_t w = 0; w < plan.size(); ++w) {
        const bool last = w + 1 == plan.size();
        queue.Write(id, plan[w].index, plan[w].subindex, plan[w].data, false,
                    [&masters, bus = buses[p], id, last](canopen::SdoAbort) {
                      if (last) masters[bus]->Send(CanFrame::Data(0x000, {0x01, id}));
                    });
        ++writes;
      }
      if (plan.empty()) masters[buses[p]]->Send(CanFrame::Data(0x000, {0x01, id}));
    }
  }

  const Duration length = seconds
                              ? std::chrono::duration_cast<Duration>(std::chrono::duration<double>(*seconds))
                              : std::chrono::duration_cast<Duration>(LongestWindow(spec));
  const auto wall_start = std::chrono::steady_clock::now();
  scheduler.AdvanceTo(scheduler.Now() + length);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  const double simulated = std::chrono::duration<double>(length).count();
  std::printf("in-process limit of %s: %zu nodes, %zu configuration writes\n", file.string().c_str(),
              nodes.size(), writes);
  for (const auto& bus : spec.bus()) {
    std::uint64_t frames = 0;
    for (const auto& port : broker.Ports(bus.name()))
      frames += port.tx_frames;
    std::printf("  %s: %llu frames\n", bus.name().c_str(), static_cast<unsigned long long>(frames));
  }
  std::printf("wall %.2f s for %.0f simulated seconds: %.0fx real time (one process, one scheduler)\n", wall,
              simulated, simulated / wall);
  nodes.clear();
  std::error_code ignored;
  std::filesystem::remove_all(state, ignored);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || argc > 3) {
    std::fprintf(stderr, "usage: %s TOPOLOGY [SIMULATED_SECONDS]\n", argv[0]);
    return 2;
  }
  spdlog::set_level(spdlog::level::warn);  // the nodes' own logs (NMT states...) are not the figure
  try {
    return Run(argv[1], argc == 3 ? std::optional(std::stod(argv[2])) : std::nullopt);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "canfleet-vt-limit: %s\n", e.what());
    return 2;
  }
}
