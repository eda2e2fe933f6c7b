// canfleet-fake-fleet: publishes the telemetry of a synthetic fleet (NodeStatus, IoSnapshot, Emcy
// and, with --orchestrator, BusStats, FaultEvent and a scenario's ScenarioStatus and Verdicts)
// through the real publishers. For the
// telemetry tests and benchmarks that need many nodes or scripted faults cheaply; a stand-in for
// node processes, not a simulation of CANopen (canfleet-node and canfleet-broker publish the real
// thing).
//
// Faults are driven by command-line timings or by commands on stdin (one per line; each answered
// with "ok <command>" on stdout once handed to the publishers):
//   fault <node> passive|bus-off|heartbeat   recover <node>   emcy <node> <hex code>
//   nmt <node> OPER|PREOP|STOP               flush            quit
//   verdict pass|FAIL|skip <name> [text]     (with --orchestrator: a Verdict of scenario "fake")
#include <poll.h>
#include <unistd.h>

#include <CLI/CLI.hpp>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "telemetry/cli_options.hpp"
#include "telemetry/dds.hpp"
#include "telemetry/node_telemetry.hpp"
#include "telemetry/orchestrator_telemetry.hpp"

namespace {

using namespace canfleet::telemetry;
using Clock = std::chrono::steady_clock;

std::atomic<bool> g_stop{false};
extern "C" void OnSignal(int) {
  g_stop = true;
}

struct FakeNode {
  std::uint8_t id = 0;
  NodeStatusSnapshot status;
  std::unique_ptr<NodeTelemetry> telemetry;
  std::uint32_t emcy_counter = 0;
  std::vector<double> inputs{0.0, 20.0};
  std::vector<double> outputs{0.0, 0.0};
};

long StatusKb(const char* field) {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind(field, 0) == 0) return std::stol(line.substr(std::string(field).size()));
  }
  return -1;
}

std::chrono::milliseconds Seconds(double s) {
  return std::chrono::milliseconds(static_cast<long>(s * 1000));
}

class FakeFleet {
 public:
  FakeFleet(const Participant& participant, const std::string& bus, int first, int count,
            const std::string& device, const std::string& names, NodeTelemetryOptions base, bool orchestrator,
            bool io)
      : bus_(bus) {
    for (int i = 0; i < count; ++i) {
      auto node = std::make_unique<FakeNode>();
      node->id = static_cast<std::uint8_t>(first + i);
      NodeTelemetryOptions options = base;
      options.bus = bus;
      options.node_id = node->id;
      options.device = device;
      if (!names.empty()) options.name = names + "-" + std::to_string(node->id);
      if (io) {
        options.inputs = {{"IN1.voltage_mV", "mV"}, {"TC1.temperature_C", "C"}};
        options.outputs = {{"OUT1.current_mA", "mA"}, {"OUT5.on", "", {"false", "true"}}};
      }
      node->status.nmt_state = NmtState::kOperational;
      node->status.heartbeat_producer_ms = 100;
      // Every node watches the first node's heartbeat (a master would watch them all).
      if (node->id != first) {
        node->status.heartbeat_consumer_count = 1;
        node->status.heartbeat_consumers[0] = {static_cast<std::uint8_t>(first), 250,
                                               HeartbeatConsumerState::kActive, NmtState::kOperational};
      }
      node->telemetry = std::make_unique<NodeTelemetry>(participant, options);
      node->telemetry->UpdateStatus(node->status);
      if (io) node->telemetry->UpdateIo(node->inputs, node->outputs);
      nodes_[node->id] = std::move(node);
    }
    if (orchestrator) {
      orchestrator_ = std::make_unique<OrchestratorTelemetry>(
          participant,
          OrchestratorTelemetryOptions{.period = base.period, .min_interval = base.min_interval});
    }
    io_ = io;
  }

  /// The periodic simulation step: PDO counters move, I/O drifts, bus statistics are refreshed.
  void Tick(double t) {
    for (auto& [id, node] : nodes_) {
      if (node->status.nmt_state == NmtState::kOperational &&
          node->status.controller_state != ControllerState::kBusOff) {
        node->status.rpdo_count += 10;
        node->status.tpdo_count += 10;
      }
      node->telemetry->UpdateStatus(node->status);
      if (io_) {
        node->inputs[0] = 5.0 + static_cast<double>(id % 10) * 0.1;
        node->inputs[1] = 20.0 + t * 0.01;
        node->telemetry->UpdateIo(node->inputs, node->outputs);
      }
    }
    if (orchestrator_) {
      ++frames_;
      BusStatsSnapshot stats;
      stats.bus = bus_;
      stats.bitrate = 500000;
      stats.mode = "realtime";
      stats.node_count = static_cast<std::uint16_t>(nodes_.size());
      stats.frames_per_second = 20.0f * static_cast<float>(std::max<std::size_t>(nodes_.size(), 1));
      stats.load_percent = stats.frames_per_second * 111.0f / 500000.0f * 100.0f;
      stats.frames_total = frames_ * 20;
      stats.error_frames = error_frames_;
      stats.top_cob_id_count = 3;
      stats.top_cob_ids[0] = {0x181, 10.0f};
      stats.top_cob_ids[1] = {0x182, 10.0f};
      stats.top_cob_ids[2] = {0x701, 10.0f};
      orchestrator_->UpdateBusStats(stats);
      if (scenario_.expectations > 0) {  // a scenario's clock, once it decided something
        scenario_.scenario_time_s = std::chrono::duration<double>(Clock::now() - scenario_start_).count();
        orchestrator_->UpdateScenario(scenario_);
      }
    }
  }

  void SendEmcy(FakeNode& node, std::uint16_t code, std::uint8_t error_register) {
    EmcyInfo emcy;
    emcy.code = code;
    emcy.error_register = error_register;
    ++node.emcy_counter;
    emcy.manufacturer = {static_cast<std::uint8_t>(node.emcy_counter),
                         static_cast<std::uint8_t>(node.emcy_counter >> 8), 0, 0, 0};
    emcy.bus_time = std::chrono::duration_cast<BusTime>(Clock::now().time_since_epoch());
    node.telemetry->PublishEmcy(emcy);
  }

  void EmcyAll() {
    for (auto& [id, node] : nodes_)
      SendEmcy(*node, static_cast<std::uint16_t>(0xFF00 + id), 0x80);
  }

  /// Applies a command; returns an error text or "".
  std::string Command(const std::string& line) {
    std::istringstream in(line);
    std::string verb;
    in >> verb;
    if (verb.empty() || verb == "flush") {
      Flush();
      return "";
    }
    int id = 0;
    in >> id;
    FakeNode* node =
        nodes_.count(static_cast<std::uint8_t>(id)) ? nodes_[static_cast<std::uint8_t>(id)].get() : nullptr;
    std::string arg;
    in >> arg;
    if (verb == "fault") {
      if (arg.empty()) arg = "passive";
      if (arg != "passive" && arg != "bus-off" && arg != "heartbeat") return "unknown fault " + arg;
      PublishFault(id, FaultAction::kInjected, arg);
      if (node) Fault(*node, arg);
      faults_[id] = arg;
      return "";
    }
    if (verb == "verdict") return Verdict(id, line);
    if (verb == "recover") {
      const auto it = faults_.find(id);
      PublishFault(id, FaultAction::kCleared, it == faults_.end() ? "passive" : it->second);
      if (it != faults_.end()) faults_.erase(it);
      if (node) Recover(*node);
      return "";
    }
    if (!node) return "no node " + std::to_string(id) + " here";
    if (verb == "emcy") {
      SendEmcy(*node, static_cast<std::uint16_t>(std::stoul(arg.empty() ? "1000" : arg, nullptr, 16)), 0x01);
      return "";
    }
    if (verb == "nmt") {
      if (arg == "OPER")
        node->status.nmt_state = NmtState::kOperational;
      else if (arg == "PREOP")
        node->status.nmt_state = NmtState::kPreOperational;
      else if (arg == "STOP")
        node->status.nmt_state = NmtState::kStopped;
      else
        return "unknown state " + arg;
      node->telemetry->UpdateStatus(node->status);
      return "";
    }
    return "unknown command " + verb;
  }

  void Flush() {
    for (auto& [id, node] : nodes_)
      node->telemetry->Flush();
    if (orchestrator_) orchestrator_->Flush();
  }

  PublisherStats Totals() const {
    PublisherStats total;
    for (const auto& [id, node] : nodes_) {
      const auto s = node->telemetry->stats();
      total.state_writes += s.state_writes;
      total.event_writes += s.event_writes;
      total.write_errors += s.write_errors;
      total.events_dropped += s.events_dropped;
    }
    return total;
  }

 private:
  void Fault(FakeNode& node, const std::string& kind) {
    auto& s = node.status;
    if (kind == "passive") {
      s.controller_state = ControllerState::kErrorPassive;
      s.tec = 128;
      s.error_register |= 0x11;  // generic + communication (CiA 301 §7.5.2.2)
      SendEmcy(node, 0x8120, s.error_register);
    } else if (kind == "bus-off") {
      s.controller_state = ControllerState::kBusOff;
      s.tec = 256;
      s.error_register |= 0x11;
      s.nmt_state = NmtState::kStopped;
    } else {  // heartbeat: the node lost its producer (consumer timed out, EMCY 8130h)
      for (std::size_t i = 0; i < s.heartbeat_consumer_count; ++i) {
        s.heartbeat_consumers[i].state = HeartbeatConsumerState::kTimedOut;
      }
      s.error_register |= 0x11;
      SendEmcy(node, 0x8130, s.error_register);
    }
    node.telemetry->UpdateStatus(s);
  }

  void Recover(FakeNode& node) {
    auto& s = node.status;
    const bool was_bus_off = s.controller_state == ControllerState::kBusOff;
    s.controller_state = ControllerState::kErrorActive;
    s.tec = 0;
    s.rec = 0;
    s.error_register = 0;
    s.nmt_state = NmtState::kOperational;
    for (std::size_t i = 0; i < s.heartbeat_consumer_count; ++i) {
      s.heartbeat_consumers[i].state = HeartbeatConsumerState::kActive;
    }
    if (was_bus_off) SendEmcy(node, 0x8140, 0x11);
    SendEmcy(node, 0x0000, 0x00);  // error reset
    node.telemetry->UpdateStatus(s);
  }

  /// "verdict pass|FAIL|skip NAME [TEXT]": scenario "fake" (source "fake.textproto") decides its
  /// next expectation; its ScenarioStatus counts it.
  std::string Verdict(int, const std::string& line) {
    if (!orchestrator_) return "verdict needs --orchestrator";
    std::istringstream in(line);
    std::string verb, result, name;
    in >> verb >> result >> name;
    std::string text;
    std::getline(in, text);
    if (!text.empty() && text.front() == ' ') text.erase(0, 1);
    VerdictResult r;
    if (result == "pass")
      r = VerdictResult::kPass;
    else if (result == "FAIL")
      r = VerdictResult::kFail;
    else if (result == "skip")
      r = VerdictResult::kSkip;
    else
      return "unknown result " + result;
    if (name.empty()) return "verdict needs a name";
    const double t = std::chrono::duration<double>(Clock::now() - scenario_start_).count();
    (r == VerdictResult::kPass   ? scenario_.passed
     : r == VerdictResult::kFail ? scenario_.failed
                                 : scenario_.skipped)++;
    const auto index =
        static_cast<std::uint16_t>(scenario_.passed + scenario_.failed + scenario_.skipped - 1);
    scenario_.step = name;
    scenario_.step_time_s = t;
    scenario_.scenario_time_s = t;
    scenario_.expectations =
        std::max<std::uint16_t>(scenario_.expectations, static_cast<std::uint16_t>(index + 1));
    scenario_.pending = 0;
    orchestrator_->UpdateScenario(scenario_);
    std::string out = ToString(r);
    out.resize(6, ' ');
    out += "fake.textproto:" + std::to_string(index + 10) + "  " + name + ": " + text;
    orchestrator_->PublishVerdict({.source = scenario_.source,
                                   .index = index,
                                   .scenario = scenario_.scenario,
                                   .cycle = scenario_.cycle,
                                   .result = r,
                                   .name = name,
                                   .line = static_cast<std::uint32_t>(index + 10),
                                   .text = out,
                                   .scenario_time_s = t});
    return "";
  }

  void PublishFault(int node, FaultAction action, const std::string& kind) {
    if (!orchestrator_) return;
    if (action == FaultAction::kInjected) ++error_frames_;
    const auto it = fault_ids_.find(node);
    std::uint32_t id;
    if (action == FaultAction::kInjected || it == fault_ids_.end()) {
      id = ++next_fault_id_;
      fault_ids_[node] = id;
    } else {
      id = it->second;
    }
    orchestrator_->PublishFault(
        {.bus = bus_,
         .fault_id = id,
         .action = action,
         .kind = kind == "heartbeat" ? "drop" : "error-frames",
         .target_node = static_cast<std::uint8_t>(node),
         .parameters = {{"mode", kind}},
         .bus_time = std::chrono::duration_cast<BusTime>(Clock::now().time_since_epoch())});
  }

  std::string bus_;
  bool io_ = false;
  std::map<std::uint8_t, std::unique_ptr<FakeNode>> nodes_;
  std::unique_ptr<OrchestratorTelemetry> orchestrator_;
  std::map<int, std::string> faults_;
  std::map<int, std::uint32_t> fault_ids_;
  std::uint32_t next_fault_id_ = 0;
  std::uint64_t frames_ = 0;
  std::uint64_t error_frames_ = 0;
  ScenarioStatusSnapshot scenario_{
      .source = "fake.textproto", .scenario = "fake", .time_mode = "real", .cycle = 1, .running = true};
  Clock::time_point scenario_start_ = Clock::now();
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Publish the telemetry of a synthetic CANopen fleet (tests, benchmarks, demos)"};
  DdsOptions dds;
  AddDdsOptions(app, dds, DdsDiscovery::kMonitorsOnly);
  std::string bus = "can0";
  std::string device = "fake-io";
  std::string names = "fake";
  int nodes = 20;
  int first = 1;
  double period = 1.0;
  double min_interval = 0.02;
  double update = 0.1;
  double duration = 0;
  double emcy_every = 0;
  double fault_every = 0;
  bool orchestrator = false;
  bool io = false;
  bool commands = false;
  int fault_node = 0;
  std::string fault_kind = "passive";
  double fault_at = 0;
  double recover_at = 0;
  app.add_option("--bus", bus, "bus name")->capture_default_str();
  app.add_option("--nodes", nodes, "how many nodes this process publishes")
      ->check(CLI::Range(0, 127))
      ->capture_default_str();
  app.add_option("--first-node", first, "node-id of the first node")
      ->check(CLI::Range(1, 127))
      ->capture_default_str();
  app.add_option("--device", device, "device name in NodeStatus")->capture_default_str();
  app.add_option("--names", names, "node names in NodeStatus: NAMES-<node-id> (empty: none)")
      ->capture_default_str();
  app.add_option("--period", period, "status period, seconds")->capture_default_str();
  app.add_option("--min-interval", min_interval, "coalescing window, seconds")->capture_default_str();
  app.add_option("--update", update, "how often each fake node hands over a status, seconds")
      ->capture_default_str();
  app.add_option("--duration", duration, "exit after this many seconds (0: on quit, EOF or a signal)");
  app.add_option("--emcy-every", emcy_every, "every node sends an EMCY (FF00h+id) this often, seconds");
  app.add_option(
      "--fault-every", fault_every,
      "inject and clear a fault on --first-node alternately this often, seconds (with --orchestrator: "
      "FaultEvent samples)");
  app.add_flag("--orchestrator", orchestrator, "also publish BusStats and FaultEvent, like the orchestrator");
  app.add_flag("--io", io, "publish simulated I/O (IoSnapshot)");
  app.add_flag("--commands", commands, "read commands from stdin");
  app.add_option("--fault-node", fault_node, "inject a fault on this node at --fault-at");
  app.add_option("--fault-kind", fault_kind, "passive, bus-off or heartbeat")->capture_default_str();
  app.add_option("--fault-at", fault_at, "seconds after start");
  app.add_option("--recover-at", recover_at, "seconds after start (0: never)");
  CLI11_PARSE(app, argc, argv);

  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
  std::signal(SIGPIPE, SIG_IGN);
  try {
    Participant participant(dds);
    FakeFleet fleet(participant, bus, first, std::min(nodes, 128 - first), device, names,
                    NodeTelemetryOptions{.period = Seconds(period), .min_interval = Seconds(min_interval)},
                    orchestrator, io);
    std::cout << "ready nodes=" << nodes << " rss_kb=" << StatusKb("VmRSS:") << std::endl;

    const auto start = Clock::now();
    auto next_tick = start;
    auto next_emcy = start + Seconds(emcy_every);
    auto next_fault = start + Seconds(fault_every);
    bool faulted = false;
    bool fault_done = fault_node == 0;
    bool recover_done = fault_node == 0 || recover_at <= 0;
    std::string pending;
    bool stdin_open = commands;
    while (!g_stop) {
      const auto now = Clock::now();
      const double t = std::chrono::duration<double>(now - start).count();
      if (duration > 0 && t >= duration) break;
      if (now >= next_tick) {
        fleet.Tick(t);
        next_tick += Seconds(update);
        if (next_tick < now) next_tick = now + Seconds(update);
      }
      if (emcy_every > 0 && now >= next_emcy) {
        fleet.EmcyAll();
        next_emcy += Seconds(emcy_every);
      }
      if (fault_every > 0 && now >= next_fault) {
        fleet.Command((faulted ? "recover " : "fault ") + std::to_string(first));
        faulted = !faulted;
        next_fault += Seconds(fault_every);
      }
      if (!fault_done && t >= fault_at) {
        fleet.Command("fault " + std::to_string(fault_node) + " " + fault_kind);
        fault_done = true;
      }
      if (!recover_done && t >= recover_at) {
        fleet.Command("recover " + std::to_string(fault_node));
        recover_done = true;
      }
      auto wake = next_tick;
      if (emcy_every > 0) wake = std::min(wake, next_emcy);
      if (fault_every > 0) wake = std::min(wake, next_fault);
      const int timeout_ms = static_cast<int>(std::max<long>(
          0, std::chrono::duration_cast<std::chrono::milliseconds>(wake - Clock::now()).count()));
      if (!stdin_open) {
        pollfd none{-1, 0, 0};
        poll(&none, 0, timeout_ms);
        continue;
      }
      pollfd input{STDIN_FILENO, POLLIN, 0};
      if (poll(&input, 1, timeout_ms) <= 0) continue;
      char buffer[512];
      const ssize_t n = read(STDIN_FILENO, buffer, sizeof buffer);
      if (n <= 0) {
        stdin_open = false;
        if (duration <= 0) break;  // EOF ends a command-driven run
        continue;
      }
      pending.append(buffer, static_cast<std::size_t>(n));
      for (std::size_t eol; (eol = pending.find('\n')) != std::string::npos;) {
        const std::string line = pending.substr(0, eol);
        pending.erase(0, eol + 1);
        if (line == "quit") g_stop = true;
        if (line == "quit" || line.empty()) continue;
        const std::string error = fleet.Command(line);
        fleet.Flush();
        std::cout << (error.empty() ? "ok " + line : "error " + error) << std::endl;
      }
    }
    fleet.Flush();
    const auto totals = fleet.Totals();
    std::cout << "stats state_writes=" << totals.state_writes << " event_writes=" << totals.event_writes
              << " write_errors=" << totals.write_errors << " events_dropped=" << totals.events_dropped
              << " rss_kb=" << StatusKb("VmRSS:") << " hwm_kb=" << StatusKb("VmHWM:") << std::endl;
  } catch (const std::exception& e) {
    std::cerr << "canfleet-fake-fleet: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
