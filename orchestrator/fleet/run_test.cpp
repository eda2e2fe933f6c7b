// `canfleet test`: one private fleet per scenario file, its expectations reported as they are
// decided, JUnit at the end.
#include "orchestrator/fleet/run_test.hpp"

#include <spdlog/sinks/basic_file_sink.h>
#include <spdlog/spdlog.h>
#include <stdlib.h>

#include <asio/io_context.hpp>
#include <cstdio>
#include <fstream>
#include <optional>

#include "bus/wire/tcp_endpoint_text.hpp"
#include "orchestrator/control/control_server.hpp"
#include "orchestrator/fleet/fleet.hpp"
#include "orchestrator/fleet/run_fleet.hpp"
#include "orchestrator/host/broker_host.hpp"
#include "orchestrator/scenario/report.hpp"
#include "orchestrator/topology/topology_loader.hpp"
#include "telemetry/cli_options.hpp"

namespace canfleet::fleet {

namespace {

namespace fs = std::filesystem;
using scenario::FileReport;

/// Private endpoints (control on port 0: the system picks one; nodes on a Unix socket in the state
/// folder), so test fleets never meet a running fleet or each other; state and logs below `root`.
void MakePrivate(topology::Topology& spec, const fs::path& root) {
  spec.mutable_orchestrator()->set_control("tcp://127.0.0.1:0");
  spec.mutable_orchestrator()->clear_listen();
  // A Unix socket of its own in the state folder: private like port 0, and cheaper per message
  // than loopback TCP (a virtual-time round is a message each way); TCP when the path is too long
  // for a socket address.
  const std::string socket_path = (fs::absolute(root) / "broker.sock").string();
  spec.mutable_orchestrator()->add_listen(socket_path.size() < 100 ? "unix://" + socket_path
                                                                   : "tcp://127.0.0.1:0");
  const fs::path old_root = spec.orchestrator().state_root();
  spec.mutable_orchestrator()->set_state_root(root.string());
  for (auto& node : *spec.mutable_node())
    if (fs::path(node.state_dir()) == old_root / node.name())
      node.set_state_dir((root / node.name()).string());
}

/// Why the fleet is not ready yet, when it never will be: a node process that ended.
std::string StartProblem(const control::Status& status) {
  for (const auto& node : status.nodes())
    if (node.process() == "exited")
      return "node " + node.name() + " exited before the fleet was ready (" + node.detail() + ")";
  return "";
}

/// What is missing for readiness, for the timeout's message.
std::string NotReady(const control::Status& status) {
  std::string out;
  for (const auto& node : status.nodes()) {
    if (node.booted() && node.detail() == "configured") continue;
    out += (out.empty() ? "" : ", ") + node.name() + " (" + node.process() +
           (node.booted() ? ", " + node.detail() : ", no boot-up seen") + ")";
  }
  return out.empty() ? "every node booted" : out;
}

class FileRun {
 public:
  FileRun(const TestOptions& options, std::ostream& out, fs::path file, fs::path root)
      : options_(options), out_(out), file_(std::move(file)), root_(std::move(root)) {
    report_.file = file_.string();
  }

  FileReport Run() {
    topology::LoadedTopology loaded;
    try {
      loaded = topology::LoadTopology(file_);
    } catch (const std::exception& e) {
      refused_ = true;
      report_.error = e.what();
      out_ << "error " << e.what() << std::endl;
      return report_;
    }
    report_.topology = loaded.spec.name();
    lines_ = loaded.step_lines;
    MakePrivate(loaded.spec, root_);
    fs::create_directories(root_);
    auto logger = std::make_shared<spdlog::logger>(
        "canfleet",
        std::make_shared<spdlog::sinks::basic_file_sink_mt>((root_ / "orchestrator.log").string(), true));
    logger->set_level(spdlog::level::from_str(options_.log_level));
    logger->flush_on(spdlog::level::info);
    auto previous = spdlog::default_logger();
    spdlog::set_default_logger(logger);
    // What the loader found that cannot work (topology_warnings.hpp): on the report, before the
    // expectations it may explain, and in the log.
    for (const auto& warning : loaded.warnings) {
      out_ << "warn  " << warning.Message() << std::endl;
      spdlog::warn("{}", warning.Message());
    }
    for (const auto& load : loaded.loads)
      spdlog::info("bus {}: periodic traffic offers {}", load.bus, load.Describe());
    Drive(loaded);
    spdlog::set_default_logger(previous);
    return report_;
  }

  bool refused() const { return refused_; }

 private:
  void Drive(const topology::LoadedTopology& loaded) {
    const auto& spec = loaded.spec;
    asio::io_context io(1);
    host::HostTime time;
    try {
      time = FleetTime(spec, options_.time);
    } catch (const std::exception& e) {
      Error(e.what());
      return;
    }
    host::BrokerHost host(io, {}, time);
    std::unique_ptr<Fleet> fleet;
    std::unique_ptr<BoundaryControlHandler> boundary;
    std::unique_ptr<control::ControlServer> control_server;
    Scheduler& scheduler = host.scheduler();
    const TimePoint begin = scheduler.Now();
    try {
      for (const auto& bus : spec.bus()) {
        host.AddBus({.name = bus.name(),
                     .bitrate = bus.bitrate(),
                     .paced = !bus.unpaced(),
                     .auto_recover = !bus.manual_recovery()});
        if (bus.socketcand_port() != 0)
          host.ServeSocketcand(bus.name(), static_cast<std::uint16_t>(bus.socketcand_port()));
      }
      for (const auto& listen : spec.orchestrator().listen())
        host.Listen(wire::Endpoint::Parse(listen));
      FleetOptions fleet_options;
      fleet_options.topology = spec;
      fleet_options.broker_endpoint = host.Endpoints().front().ToString();
      fleet_options.node_binary = FindNodeBinary(options_.node_binary);
      fleet_options.node_arguments = telemetry::DdsArguments(options_.dds);
      if (!options_.telemetry) fleet_options.node_arguments.push_back("--no-telemetry");
      fleet_options.wall_origin = host.wall_origin();
      fleet_options.seed = options_.seed ? *options_.seed : spec.time().seed();
      fleet_options.scenario_source = report_.file;
      fleet_options.step_lines = lines_;
      if (!options_.capture.empty())
        fleet_options.capture_folders = CaptureFoldersAt(options_.capture, spec.orchestrator().state_root());
      UseHostTime(fleet_options, host.conductor());
      fleet = std::make_unique<Fleet>(io, scheduler, host.broker(), host.server(), std::move(fleet_options));
      control_server =
          std::make_unique<control::ControlServer>(io, ControlHandlerFor(*fleet, host.conductor(), boundary));
      if (!options_.capture.empty()) {
        fs::create_directories(options_.capture);
        for (const auto& bus : spec.bus()) {
          control::CaptureStart capture;
          capture.set_bus(bus.name());
          capture.set_format("candump");
          capture.set_path(
              (fs::absolute(options_.capture) / (file_.stem().string() + "-" + bus.name() + ".log"))
                  .string());
          fleet->StartCapture(capture);
        }
      }
      const auto bound = control_server->Listen(spec.orchestrator().control());
      spdlog::info("canfleet test {}: control API on tcp://{}, nodes connect to {}", report_.file,
                   wire::TcpEndpointText(bound), host.Endpoints().front().ToString());
    } catch (const std::exception& e) {
      Error(std::string("the fleet did not start: ") + e.what());
      return;
    }
    if (options_.telemetry && host.StartTelemetry(options_.dds, std::chrono::seconds(1))) {
      // The scenario's status and verdicts on DDS (issue 29), as `canfleet up` publishes them.
      publisher_ = host.publisher();
      scenario_telemetry_ = PublishScenario(*fleet, *publisher_, scheduler);
    }

    bool stopping = false;
    auto shutdown = [&](const std::string& why) {
      if (stopping) return;
      stopping = true;
      spdlog::info("{}: stopping the fleet", why);
      fleet->Stop([&] {
        control_server->Close();
        host.Stop();
      });
    };
    // Until the fleet is ready: a node that ended, or the time running out, is an error.
    std::function<void()> watch = [&] {
      if (stopping || fleet->Ready()) return;
      const control::Status status = fleet->Status();
      std::string problem = StartProblem(status);
      if (problem.empty() && scheduler.Now() - begin >= options_.ready_timeout)
        problem =
            "the fleet was not ready after " +
            std::to_string(std::chrono::duration_cast<std::chrono::seconds>(options_.ready_timeout).count()) +
            " s: " + NotReady(status);
      if (!problem.empty()) {
        Error(problem + " (logs: " + (root_ / "logs").string() + ")");
        return shutdown("not started");
      }
      watchdog_->StartAfter(std::chrono::milliseconds(250));
    };
    watchdog_ = std::make_unique<Timer>(scheduler, [&] { watch(); });
    watchdog_->StartAfter(std::chrono::milliseconds(250));

    fleet->OnReady([&] {
      char ready[96];
      std::snprintf(ready, sizeof ready, ": fleet ready (%d nodes, %.2f s)", spec.node_size(),
                    std::chrono::duration<double>(scheduler.Now() - begin).count());
      out_ << "      " << report_.file << ready << std::endl;
    });
    fleet->OnExpectation(
        [&](const scenario::Result& result) { out_ << fleet->ResultLine(result) << std::endl; });
    std::optional<TimePoint> scenario_end;
    fleet->OnScenarioDone([&] {
      scenario_end = scheduler.Now();
      fleet->StopCaptures();
      shutdown("scenario done");
    });
    host.OnSignal([&](const char* name) {
      Error(std::string("interrupted (") + name + ")");
      shutdown(name);
    });
    fleet->Start();
    if (auto* conductor = host.conductor()) conductor->HoldUntilJoined(NodeProcesses(spec), kJoinTimeout);
    io.run();
    watchdog_.reset();
    scenario_telemetry_.reset();  // before the fleet, whose hooks call it
    publisher_ = nullptr;
    if (auto* conductor = host.conductor()) {
      report_.factor = conductor->Factor();
      const auto& st = conductor->Stats();
      spdlog::info(
          "virtual time: {} rounds, {} grants, {} frames put on the buses, {} evictions, {} early stops, {} "
          "causality errors, factor {:.1f}",
          st.rounds, st.grants, st.frames, st.evictions, st.early_stops, st.causality_errors, report_.factor);
    }

    report_.results = fleet->ScenarioResults();
    if (const auto origin = fleet->ScenarioOrigin()) report_.origin = *origin;
    for (const auto& r : report_.results)
      report_.lines.push_back(
          r.step < static_cast<int>(lines_.size()) ? lines_[static_cast<std::size_t>(r.step)] : 0);
    // Expectations the run never judged (the fleet did not start, or was interrupted).
    for (auto& r : report_.results) {
      if (r.verdict.outcome != scenario::Outcome::kPending) continue;
      r.verdict.outcome = scenario::Outcome::kSkipped;
      r.verdict.detail = report_.error.empty() ? "not judged" : "not judged: " + report_.error;
    }
    report_.seconds = std::chrono::duration<double>(scenario_end.value_or(scheduler.Now()) - begin).count();
    if (report_.factor > 0) {
      char line[160];
      std::snprintf(line, sizeof line, ": virtual time, %.1f s simulated at %.1fx real time", report_.seconds,
                    report_.factor);
      out_ << "      " << report_.file << line << std::endl;
    }
    control_server.reset();
    fleet.reset();
  }

  void Error(const std::string& what) {
    if (!report_.error.empty()) return;
    report_.error = what;
    const std::string line = "error " + report_.file + ": " + what;
    out_ << line << std::endl;
    // A monitor sees the file's error too (Verdict index kFileVerdictIndex).
    if (publisher_ != nullptr)
      publisher_->PublishVerdict({.source = report_.file,
                                  .index = telemetry::kFileVerdictIndex,
                                  .scenario = report_.topology,
                                  .cycle = 1,
                                  .result = telemetry::VerdictResult::kError,
                                  .name = "fleet",
                                  .line = 0,
                                  .text = line,
                                  .scenario_time_s = 0});
  }

  const TestOptions& options_;
  std::ostream& out_;
  fs::path file_, root_;
  FileReport report_;
  std::vector<int> lines_;
  std::unique_ptr<Timer> watchdog_;
  telemetry::OrchestratorTelemetry* publisher_ = nullptr;  ///< while the fleet runs with --telemetry
  std::unique_ptr<broker::ScenarioTelemetry> scenario_telemetry_;
  bool refused_ = false;
};

std::string SafeName(std::string name) {
  for (auto& c : name)
    if (c == '/' || c == ' ') c = '_';
  return name;
}

}  // namespace

int RunTests(const TestOptions& options, std::ostream& out) {
  fs::path base = options.state_dir;
  const bool temporary = base.empty();
  if (temporary) {
    std::string pattern = (fs::temp_directory_path() / "canfleet-test-XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) {
      out << "canfleet test: cannot create a temporary folder in " << fs::temp_directory_path().string()
          << "\n";
      return 1;
    }
    base = pattern;
  }
  scenario::JunitRun run;
  run.seed = options.seed;
  run.time_mode = options.time.mode.empty() ? "topology" : options.time.mode;
  bool refused = false;
  double seconds = 0;
  for (std::size_t i = 0; i < options.files.size(); ++i) {
    const fs::path root = base / (std::to_string(i + 1) + "-" + SafeName(options.files[i].stem().string()));
    FileRun file_run(options, out, options.files[i], root);
    run.files.push_back(file_run.Run());
    refused = refused || file_run.refused();
    seconds += run.files.back().seconds;
  }
  scenario::Totals totals;
  for (const auto& f : run.files)
    totals.Add(f);
  out << scenario::SummaryLine(totals, run.files.size(), seconds) << std::endl;
  if (!options.junit.empty()) {
    std::ofstream junit(options.junit, std::ios::trunc);
    scenario::WriteJunit(junit, run);
    if (!junit) out << "canfleet test: cannot write " << options.junit.string() << "\n";
  }
  const bool passed = totals.AllPassed() && !refused;
  if (temporary && passed) {
    std::error_code ec;
    fs::remove_all(base, ec);
  } else {
    out << "state and logs: " << base.string() << "\n";
  }
  if (refused) return 2;
  return passed ? 0 : 1;
}

}  // namespace canfleet::fleet
