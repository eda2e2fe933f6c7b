#include "orchestrator/fleet/fleet.hpp"
#include "orchestrator/host/broker_host.hpp"

#include <spdlog/spdlog.h>

#include <asio/post.hpp>

#include "orchestrator/capture/capture_tap.hpp"
#include "orchestrator/topology/configuration_plan.hpp"
#include "vocabulary/nearest_names.hpp"

namespace canfleet::fleet {

namespace {

std::string DeviceLabel(const topology::Node& node) {
  if (!node.device().empty()) return node.device();
  return "eds:" + std::filesystem::path(node.eds()).filename().string();
}

LaunchSpec NodeLaunch(const FleetNode& node, const FleetOptions& options) {
  LaunchSpec launch;
  launch.binary = options.node_binary;
  auto& args = launch.args;
  args = {"--name", node.name()};
  if (!node.spec.device().empty()) args.insert(args.end(), {"--device", node.spec.device()});
  if (!node.spec.eds().empty()) args.insert(args.end(), {"--eds", node.spec.eds()});
  for (const auto id : node.spec.node_id())
    args.insert(args.end(), {"--node-id", std::to_string(id)});
  for (const auto& bus : node.buses)
    args.insert(args.end(), {"--bus", bus + "@" + options.broker_endpoint});
  if (!node.spec.state_dir().empty()) args.insert(args.end(), {"--state-dir", node.spec.state_dir()});
  if (node.spec.has_serial()) args.insert(args.end(), {"--serial", std::to_string(node.spec.serial())});
  if (!node.spec.log_level().empty()) args.insert(args.end(), {"--log-level", node.spec.log_level()});
  // Sorted, so the command line (and the log) is the same on every run.
  std::map<std::string, std::string> io(node.spec.io().begin(), node.spec.io().end());
  for (const auto& [name, value] : io)
    args.insert(args.end(), {"--io", name + "=" + value});
  args.insert(args.end(), options.node_arguments.begin(), options.node_arguments.end());
  launch.log_file =
      std::filesystem::path(options.topology.orchestrator().state_root()) / "logs" / (node.name() + ".log");
  return launch;
}

RestartPolicy PolicyOf(const topology::Node& node) {
  RestartPolicy policy;
  policy.on_failure = node.restart().policy() == topology::Restart::ON_FAILURE;
  policy.max_restarts = node.restart().max_restarts();
  if (node.restart().backoff_ms() > 0)
    policy.backoff = std::chrono::milliseconds(node.restart().backoff_ms());
  return policy;
}

CaptureFolders CaptureFoldersOf(const FleetOptions& options) {
  if (options.capture_folders) return *options.capture_folders;
  const auto& root = options.topology.orchestrator().state_root();
  return CaptureFoldersAt(std::filesystem::path(root) / "captures", root);
}

}  // namespace

Fleet::Fleet(asio::io_context& io, Scheduler& scheduler, broker::Broker& broker,
             transport::BrokerServer& server, FleetOptions options)
    : io_(io),
      scheduler_(scheduler),
      broker_(broker),
      server_(server),
      options_(std::move(options)),
      origin_(scheduler.Now()),
      wall_origin_(options_.wall_origin.value_or(WallClockOrigin(scheduler))),
      supervisor_(io, scheduler,
                  Supervisor::Hooks{
                      .started =
                          [this](const std::string& name, pid_t pid) {
                            // Virtual time waits for the process (real time to start it is no
                            // simulated time): it joins at the time it was started.
                            if (options_.conductor != nullptr) {
                              const std::string clock_id = name + "#" + std::to_string(pid);
                              awaited_clock_[name] = clock_id;
                              options_.conductor->HoldUntilProcessJoins(clock_id, host::kJoinTimeout);
                            }
                            if (const FleetNode* node = FindNode(name)) {
                              for (std::size_t p = 0; p < node->buses.size(); ++p) {
                                tracker_.Forget(node->buses[p], node->node_ids[p]);
                                runtime_[{name, p}] = {};
                              }
                            }
                          },
                      .ended =
                          [this](const std::string& name, const std::string&, bool) {
                            const auto it = awaited_clock_.find(name);
                            if (it == awaited_clock_.end()) return;
                            if (options_.conductor != nullptr) options_.conductor->StopWaitingFor(it->second);
                            awaited_clock_.erase(it);
                          },
                  }),
      captures_(broker, wall_origin_, CaptureFoldersOf(options_)) {
  for (const auto& spec : options_.topology.node()) {
    FleetNode node;
    node.spec = spec;
    node.buses.assign(spec.bus().begin(), spec.bus().end());
    for (std::size_t p = 0; p < node.buses.size(); ++p) {
      const auto id = spec.node_id_size() == 1 ? spec.node_id(0) : spec.node_id(static_cast<int>(p));
      node.node_ids.push_back(static_cast<std::uint8_t>(id));
    }
    node.device_label = DeviceLabel(spec);
    nodes_.push_back(std::move(node));
  }
  for (const auto& bus : broker_.Buses()) {
    auto master = std::make_unique<MasterPort>(broker_, bus);
    master->AddObserver(
        [this, bus](const CanFrame& frame, BusTime) { tracker_.Observe(bus, frame, scheduler_.Now()); });
    sdo_[bus] = std::make_unique<SdoQueue>(*master, scheduler_);
    masters_[bus] = std::move(master);
    // Virtual time: the master answers at once what it hears (a boot-up, an SDO answer); per-node
    // lookahead must know (TimeConductor::AddReactor).
    if (options_.conductor != nullptr)
      reactors_.push_back(options_.conductor->AddReactor(bus, [this, bus] {
        using Reaction = transport::TimeConductor::Reaction;
        if (runner_ && runner_->MayReadOnFrames()) return Reaction::kAnything;
        return sdo_.at(bus)->Pending() > 0 ? Reaction::kBootUpsAndAnswers : Reaction::kBootUps;
      }));
  }
  tracker_.OnBootUp([this](const std::string& bus, std::uint8_t id) { OnBootUp(bus, id); });
  tracker_.OnEmcy([this](const std::string& bus, std::uint8_t id, const SeenEmcy& emcy) {
    const FleetNode* node = NodeAt(bus, id);
    // A node with several CAN ports has an EMCY producer on each: say which one sent it.
    const std::string port = node && node->buses.size() > 1 ? " (" + bus + ")" : "";
    spdlog::info("{}: EMCY {:04X}h, error register {:02X}h, data {:02X} {:02X} {:02X} {:02X} {:02X}{}",
                 node ? node->name() : bus + "#" + std::to_string(id), emcy.code, emcy.error_register,
                 emcy.manufacturer[0], emcy.manufacturer[1], emcy.manufacturer[2], emcy.manufacturer[3],
                 emcy.manufacturer[4], port);
  });

  faults_ = std::make_unique<FaultManager>(FaultManager::Context{
      .broker = broker_,
      .scheduler = scheduler_,
      .supervisor = supervisor_,
      .find_node = [this](const std::string& name) { return FindNode(name); },
      .unknown_node = [this](const std::string& name) { return UnknownNode(name); },
      .origin = origin_,
      .on_event =
          [this](const control::FaultStatus& status, bool started) {
            if (on_fault_event_) on_fault_event_(status, started);
          },
      .seed = options_.seed,
  });
  for (const auto& node : nodes_)
    if (!node.external()) supervisor_.Add(node.name(), NodeLaunch(node, options_), PolicyOf(node.spec));
  WatchScenario();

  std::vector<ExternalAdoption::Port> external_ports;
  for (const auto& node : nodes_)
    if (node.external())
      for (std::size_t p = 0; p < node.buses.size(); ++p)
        external_ports.push_back({node.name(), node.buses[p], node.node_ids[p]});
  adoption_ = std::make_unique<ExternalAdoption>(
      ExternalAdoption::Context{
          .scheduler = scheduler_,
          .attached = [this](
                          const std::string& bus,
                          const std::string& name) { return broker_.NewestPortNamed(bus, name).has_value(); },
          .booted =
              [this](const std::string& bus, std::uint8_t id) {
                const NodeLiveState* live = tracker_.Find(bus, id);
                return live && live->booted;
              },
          .reset_communication =
              [this](const ExternalAdoption::Port& port) { SendNmt(port.bus, 0x82, port.node_id); },
      },
      std::move(external_ports));
}

Fleet::~Fleet() {
  if (options_.conductor != nullptr)
    for (const std::uint64_t id : reactors_)
      options_.conductor->RemoveReactor(id);
}

void Fleet::Start() {
  spdlog::info("topology {}: {} bus(es), {} node(s)", options_.topology.name(), masters_.size(),
               nodes_.size());
  for (const auto& node : nodes_)
    if (node.external()) spdlog::info("{}: external, waiting for it to attach", node.name());
  if (options_.start_processes) supervisor_.StartAll();
  adoption_->Start();
}

void Fleet::Stop(std::function<void()> done) {
  // The scenario ends here: what was decided stays readable, nothing more runs or is judged.
  final_results_ = runner_->Results();
  final_origin_ = runner_->origin();
  repeat_timer_.reset();
  scenario_taps_.clear();
  runner_.reset();
  supervisor_.StopAll(std::move(done));
}

double Fleet::Uptime() const {
  return std::chrono::duration<double>(scheduler_.Now() - origin_).count();
}

const FleetNode* Fleet::FindNode(const std::string& name) const {
  for (const auto& node : nodes_)
    if (node.name() == name) return &node;
  return nullptr;
}

const FleetNode& Fleet::NodeOrThrow(const std::string& name) const {
  if (name.empty()) throw std::invalid_argument("say which node");
  const FleetNode* node = FindNode(name);
  if (!node) throw std::invalid_argument(UnknownNode(name));
  return *node;
}

std::string Fleet::UnknownNode(const std::string& name) const {
  std::vector<std::string> names;
  for (const auto& n : nodes_)
    names.push_back(n.name());
  std::string out = "no node called '" + name + "' in this fleet";
  if (const auto nearest = NearestNames(name, names); !nearest.empty())
    out += "; nearest: " + JoinNames(nearest);
  return out + "; all: canfleet status";
}

std::optional<std::uint8_t> Fleet::NodeIdOn(const std::string& name, const std::string& bus) const {
  const FleetNode* node = FindNode(name);
  if (!node) return std::nullopt;
  const int port = node->PortOn(bus);
  if (port < 0) return std::nullopt;
  return node->node_ids[static_cast<std::size_t>(port)];
}

const FleetNode* Fleet::NodeAt(const std::string& bus, std::uint8_t node_id) const {
  for (const auto& node : nodes_) {
    const int port = node.PortOn(bus);
    if (port >= 0 && node.node_ids[static_cast<std::size_t>(port)] == node_id) return &node;
  }
  return nullptr;
}

// ---- boot-up, configuration, readiness ----

void Fleet::OnBootUp(const std::string& bus, std::uint8_t node_id) {
  const FleetNode* node = NodeAt(bus, node_id);
  if (!node) {
    spdlog::info("{}: boot-up of node-ID {}, which the topology does not name", bus, node_id);
    return;
  }
  spdlog::info("{}: boot-up on {} (node-ID {})", node->name(), bus, node_id);
  Configure(*node, static_cast<std::size_t>(node->PortOn(bus)));
}

void Fleet::Configure(const FleetNode& node, std::size_t port) {
  auto& runtime = runtime_[{node.name(), port}];
  runtime.configured = false;
  runtime.configuration = "configuring";
  std::vector<topology::PlannedWrite> plan;
  auto failures = std::make_shared<std::vector<std::string>>();
  try {
    plan = topology::PlanConfiguration(
        node.spec, node.buses, node.node_ids, port,
        [this](const std::string& other, const std::string& on_bus) { return NodeIdOn(other, on_bus); });
  } catch (const std::exception& e) {
    failures->push_back(std::string("configuration refused: ") + e.what());
    spdlog::error("{}: {}", node.name(), failures->back());
  }
  const std::string bus = node.buses[port];
  const std::uint8_t id = node.node_ids[port];
  const std::string name = node.name();
  auto steps = std::make_shared<std::vector<topology::PlannedWrite>>(std::move(plan));
  // Each SDO completion owns the continuation (a strong reference); the continuation itself only
  // holds a weak one, so the chain frees itself after the last step.
  auto next = std::make_shared<std::function<void(std::size_t)>>();
  std::weak_ptr<std::function<void(std::size_t)>> weak_next = next;
  *next = [this, steps, failures, weak_next, bus, id, name, port](std::size_t i) {
    if (i < steps->size()) {
      const topology::PlannedWrite& write = (*steps)[i];
      auto self = weak_next.lock();
      sdo_.at(bus)->Write(id, write.index, write.subindex, write.data, false,
                          [steps, failures, self, i, name](canopen::SdoAbort abort) {
                            const topology::PlannedWrite& done = (*steps)[i];
                            if (abort != canopen::SdoAbort::kNone) {
                              failures->push_back(done.what + ": " + DescribeAbort(abort));
                              spdlog::error("{}: configuring {} failed: {}", name, done.what,
                                            DescribeAbort(abort));
                            } else {
                              spdlog::debug("{}: configured {}", name, done.what);
                            }
                            (*self)(i + 1);
                          });
      return;
    }
    auto& rt = runtime_[{name, port}];
    rt.configured = true;
    rt.configuration = failures->empty() ? "configured" : "configured with errors: " + failures->front();
    if (options_.topology.orchestrator().start_nodes()) SendNmt(bus, 0x01, id);
    spdlog::info("{}: {} ({} write(s)){}", name, rt.configuration, steps->size(),
                 options_.topology.orchestrator().start_nodes() ? ", NMT start" : "");
    CheckReady();
  };
  (*next)(0);
}

void Fleet::CheckReady() {
  if (ready_) return;
  for (const auto& node : nodes_) {
    for (std::size_t p = 0; p < node.buses.size(); ++p) {
      auto it = runtime_.find({node.name(), p});
      if (it == runtime_.end() || !it->second.configured) return;
    }
  }
  ready_ = true;
  spdlog::info("fleet ready: every node booted and configured ({:.2f} s)", Uptime());
  StartScenario();
  if (on_ready_) on_ready_();
}

// ---- NMT ----

void Fleet::SendNmt(const std::string& bus, std::uint8_t command, std::uint8_t node_id) {
  // CiA 301 §7.2.8.3.1: COB-ID 000h, byte 0 command specifier, byte 1 node-ID (0 = all).
  masters_.at(bus)->Send(CanFrame::Data(0x000, {command, node_id}));
}

std::string Fleet::Nmt(const control::NmtCommand& command) {
  std::uint8_t cs = 0;
  switch (command.action()) {
    case control::NMT_START:
      cs = 0x01;
      break;
    case control::NMT_STOP:
      cs = 0x02;
      break;
    case control::NMT_PREOP:
      cs = 0x80;
      break;
    case control::NMT_RESET:
      cs = 0x81;
      break;
    case control::NMT_RESET_COMM:
      cs = 0x82;
      break;
    default:
      throw std::invalid_argument("say which NMT command");
  }
  char text[48];
  if (command.node().empty()) {
    for (const auto& [bus, master] : masters_)
      SendNmt(bus, cs, 0);
    std::snprintf(text, sizeof text, "NMT %02Xh sent to every node", cs);
    return text;
  }
  const FleetNode& node = NodeOrThrow(command.node());
  for (std::size_t p = 0; p < node.buses.size(); ++p)
    SendNmt(node.buses[p], cs, node.node_ids[p]);
  std::snprintf(text, sizeof text, "NMT %02Xh sent to ", cs);
  return text + node.name();
}

}  // namespace canfleet::fleet
