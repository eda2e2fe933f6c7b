#pragma once
/// @file The running fleet (`canfleet up`): the orchestrator's side of every node — its process
/// (Supervisor), what the master sees of it (NodeTracker), its configuration after boot-up, the
/// faults injected into it — and the control API's answers (ControlHandler).
///
/// Threading: everything runs on the event loop's thread, like the Broker it drives.

#include <asio/io_context.hpp>
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bus/capture/capture_writer.hpp"
#include "clock/scheduler.hpp"
#include "clock/wall_clock.hpp"
#include "orchestrator/broker/broker.hpp"
#include "orchestrator/broker_telemetry/scenario_telemetry.hpp"
#include "orchestrator/control/control_handler.hpp"
#include "orchestrator/fleet/asked_expectation.hpp"
#include "orchestrator/fleet/external_adoption.hpp"
#include "orchestrator/fleet/fault_manager.hpp"
#include "orchestrator/fleet/fleet_node.hpp"
#include "orchestrator/fleet/frame_feed.hpp"
#include "orchestrator/fleet/master_port.hpp"
#include "orchestrator/fleet/node_tracker.hpp"
#include "orchestrator/fleet/scenario_tap.hpp"
#include "orchestrator/fleet/sdo_queue.hpp"
#include "orchestrator/fleet/supervisor.hpp"
#include "orchestrator/scenario/scenario_runner.hpp"
#include "orchestrator/topology/canfleet_topology.pb.h"
#include "orchestrator/transport/broker_server.hpp"
#include "orchestrator/transport/time_conductor.hpp"

namespace canfleet::fleet {

struct FleetOptions {
  topology::Topology topology;  ///< loaded and validated, defaults applied
  std::filesystem::path node_binary;
  std::string broker_endpoint;  ///< where started nodes connect ("tcp://127.0.0.1:29600")
  bool start_processes = true;  ///< false: `canfleet up --no-start`
  /// Added to every node's command line: the DDS options `canfleet up` was given
  /// (telemetry::DdsArguments), so its nodes publish where it does.
  std::vector<std::string> node_arguments;
  /// Wall-clock time of scheduler time 0 for dumps and captures: the process's one origin
  /// (host::BrokerHost::wall_origin), which socketcand uses too. Unset: read when the fleet starts.
  std::optional<WallTime> wall_origin;
  /// Run the scenario again after topology.scenario_repeat_ms (`canfleet up`); false: once
  /// (`canfleet test` judges one run).
  bool repeat_scenario = false;
  /// Virtual time: the broker's time conductor (status shows simulated time and the factor).
  transport::TimeConductor* conductor = nullptr;
  /// Seed of the random draws of faults that give none (topology `time.seed`).
  std::uint64_t seed = 0;
  /// The topology file as given (`canfleet up FILE`, `canfleet test FILE`): result lines and
  /// telemetry's verdicts name it. Empty: the topology's name.
  std::string scenario_source;
  /// Where the control API may have captures written (capture_path.hpp). Default: base
  /// <state root>/captures, allowed the state root.
  std::optional<CaptureFolders> capture_folders;
  /// The line of each scenario step in that file (topology::LoadedTopology::step_lines).
  std::vector<int> step_lines;
};

/// Where the fleet's scenario stands: the runner's progress in the current cycle.
struct ScenarioNow {
  scenario::Progress progress;
  int cycle = 0;                    ///< 1 for the first run, 2 for the first repetition, ... (0: none yet)
  std::optional<TimePoint> origin;  ///< this cycle's start
  TimePoint now{};                  ///< the fleet's scheduler time
};

class Fleet final : public control::ControlHandler, public scenario::FleetProbe {
 public:
  Fleet(asio::io_context& io, Scheduler& scheduler, broker::Broker& broker, transport::BrokerServer& server,
        FleetOptions options);
  ~Fleet() override;

  /// Starts the node processes.
  void Start();
  /// Runs once every node has booted (boot-up seen on each of its ports) and been configured.
  void OnReady(std::function<void()> handler) { on_ready_ = std::move(handler); }
  /// A control client asked for a shutdown.
  void OnShutdownRequest(std::function<void()> handler) { on_shutdown_request_ = std::move(handler); }
  /// Stops every node process (SIGTERM, then SIGKILL after a grace time); `done` runs after.
  void Stop(std::function<void()> done);
  /// Starts a capture of a bus to a file, as the control API's CaptureStart does (`canfleet test
  /// --capture`). @throws std::invalid_argument or std::system_error.
  control::CaptureStarted StartCapture(const control::CaptureStart& request) {
    return captures_.Start(request);
  }
  /// Ends every capture now (`canfleet test` ends them with the scenario, so a capture in virtual
  /// time ends at the same simulated instant on every run, not when the processes happen to stop).
  void StopCaptures() { captures_.Stop(0); }

  /// A fault began or ended (the fault event log): for telemetry.
  void OnFaultEvent(std::function<void(const control::FaultStatus&, bool started)> handler) {
    on_fault_event_ = std::move(handler);
  }

  control::Status Status() const;

  /// Adds a handler for every expectation of the scenario decided (issue 21; `canfleet test`
  /// prints it, telemetry publishes it).
  void OnExpectation(std::function<void(const scenario::Result&)> handler) {
    on_expectation_.push_back(std::move(handler));
  }
  /// Adds a handler for every change of the scenario's state: it started, a step began, an
  /// expectation was decided, it ended (telemetry's ScenarioStatus).
  void OnScenarioChange(std::function<void()> handler) { on_scenario_change_.push_back(std::move(handler)); }
  /// The result line of a decided expectation, as the log and `canfleet test` print it:
  /// "pass  topologies/demo.textproto:284  quad-6-emcy: ... at t=42.993 s".
  std::string ResultLine(const scenario::Result& result) const;
  /// The line of scenario step `step` in the file (0: unknown).
  int StepLine(int step) const;
  /// The file as results name it (FleetOptions::scenario_source, else the topology's name).
  const std::string& ScenarioSource() const {
    return options_.scenario_source.empty() ? options_.topology.name() : options_.scenario_source;
  }
  ScenarioNow Scenario() const;
  const std::string& TopologyName() const { return options_.topology.name(); }
  bool VirtualTime() const { return options_.conductor != nullptr; }
  bool HasScenario() const { return !options_.topology.scenario().empty(); }
  /// Every scenario step ran and every expectation was decided.
  void OnScenarioDone(std::function<void()> handler) { on_scenario_done_ = std::move(handler); }
  /// Every expectation of the scenario, decided or not, in file order.
  std::vector<scenario::Result> ScenarioResults() const {
    return runner_ ? runner_->Results() : final_results_;
  }
  /// When the scenario started (the fleet was ready); unset before.
  std::optional<TimePoint> ScenarioOrigin() const { return runner_ ? runner_->origin() : final_origin_; }
  bool Ready() const { return ready_; }

  // scenario::FleetProbe: what the scenario's expectations read (fleet_scenario.cpp).
  void ReadSdo(const scenario::PortAddress& port, std::size_t port_index, std::uint16_t index,
               std::uint8_t subindex, SdoDone done) override;
  void ReadIo(const std::string& node, const std::string& name, IoDone done) override;
  std::string NmtState(const scenario::PortAddress& port) const override;
  std::string ControllerState(const scenario::PortAddress& port) const override;
  double LoadPercent(const std::string& bus) const override;

  // control::ControlHandler
  void Handle(const control::Request& request, std::shared_ptr<control::Responder> responder) override;

 private:
  struct PortRuntime {
    bool configured = false;
    std::string configuration;  ///< "", "configuring", "configured", or what failed
  };

  const FleetNode* FindNode(const std::string& name) const;
  const FleetNode& NodeOrThrow(const std::string& name) const;
  /// "no node called 'quad-9' in this fleet; nearest: quad-5, quad-6; all: canfleet status".
  std::string UnknownNode(const std::string& name) const;
  std::optional<std::uint8_t> NodeIdOn(const std::string& name, const std::string& bus) const;
  const FleetNode* NodeAt(const std::string& bus, std::uint8_t node_id) const;

  void OnBootUp(const std::string& bus, std::uint8_t node_id);
  void Configure(const FleetNode& node, std::size_t port);
  void CheckReady();
  void StartScenario();
  void SendNmt(const std::string& bus, std::uint8_t command, std::uint8_t node_id);
  std::string Nmt(const control::NmtCommand& command);

  // Requests that answer later (SDO, remote I/O) get the responder; the others return a Response.
  void SdoRead(const control::Request& request, std::shared_ptr<control::Responder> responder);
  void SdoWrite(const control::SdoWrite& write, std::function<void(std::string error)> done);
  /// A node's answer to a simulated-I/O request: an error (bad_request: the node refused the name,
  /// type or range), or its values and notice.
  struct IoAnswer {
    std::string error;
    bool bad_request = false;
    std::string notice;
    control::IoValues values;
  };
  void IoRequest(const std::string& node, wire::NodeRequest request,
                 std::function<void(const IoAnswer&)> done);
  void StartDump(const control::Request& request, std::shared_ptr<control::Responder> responder);
  // fleet_clock.cpp: a test driving virtual time, and expectations asked through the control API.
  void AdvanceClock(const control::Request& request, std::shared_ptr<control::Responder> responder);
  void StartExpect(const control::Request& request, std::shared_ptr<control::Responder> responder);
  void RunStep(const topology::Step& step);

  double Uptime() const;

  asio::io_context& io_;
  Scheduler& scheduler_;
  broker::Broker& broker_;
  transport::BrokerServer& server_;
  FleetOptions options_;
  TimePoint origin_;
  WallTime wall_origin_;

  std::vector<FleetNode> nodes_;
  std::map<std::string, std::unique_ptr<MasterPort>> masters_;  ///< by bus
  std::map<std::string, std::unique_ptr<SdoQueue>> sdo_;        ///< by bus
  std::vector<std::uint64_t> reactors_;  ///< the masters, as the time conductor knows them
  std::map<std::pair<std::string, std::size_t>, PortRuntime> runtime_;  ///< (node, port)
  NodeTracker tracker_;
  Supervisor supervisor_;
  std::unique_ptr<FaultManager> faults_;
  std::unique_ptr<ExternalAdoption> adoption_;  ///< running external nodes that attach without a boot-up
  Captures captures_;
  void WatchScenario();
  void RepeatScenario();
  std::unique_ptr<scenario::ScenarioRunner> runner_;
  std::unique_ptr<Timer> repeat_timer_;  ///< the next run of a repeating scenario
  int scenario_run_ = 1;
  std::vector<scenario::Result> final_results_;  ///< after Stop
  std::optional<TimePoint> final_origin_;
  std::vector<std::unique_ptr<ScenarioTap>> scenario_taps_;  ///< listen-only, one per bus, for expectations
  bool ready_ = false;
  std::map<std::uint64_t, std::unique_ptr<AskedExpectation>> asked_;
  /// Virtual time: each node's latest process ("name#pid"), awaited by the conductor until it joins.
  std::map<std::string, std::string> awaited_clock_;  ///< ExpectRequests being judged
  std::uint64_t next_asked_ = 1;

  std::function<void()> on_ready_;
  std::function<void()> on_shutdown_request_;
  std::function<void(const control::FaultStatus&, bool)> on_fault_event_;
  std::vector<std::function<void(const scenario::Result&)>> on_expectation_;
  std::vector<std::function<void()>> on_scenario_change_;
  std::function<void()> on_scenario_done_;
  void ScenarioChanged();
};

/// Publishes `fleet`'s scenario over DDS through `publisher` (issue 29): its ScenarioStatus (every
/// second, and at once when a step begins or an expectation is decided) and a Verdict per decided
/// expectation, with the result line the log and `canfleet test` print. Null when the topology
/// has no scenario. The result must be destroyed before `fleet` and `publisher`.
std::unique_ptr<broker::ScenarioTelemetry> PublishScenario(Fleet& fleet,
                                                           telemetry::OrchestratorTelemetry& publisher,
                                                           Scheduler& scheduler);

}  // namespace canfleet::fleet
