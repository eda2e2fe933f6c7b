// The fleet's scenario (issue 21): action steps run by the scenario runner on the fleet's
// scheduler, expectations judged on what the orchestrator sees — every frame of each bus through
// a listen-only tap (error frames included), and the reads of scenario::FleetProbe answered
// here: SDO uploads by the master's client, simulated I/O over the node's broker connection, NMT
// states from heartbeats, controller states and bus load from the broker.
#include <spdlog/spdlog.h>

#include "orchestrator/fleet/fleet.hpp"
#include "orchestrator/fleet/scenario_tap.hpp"
#include "orchestrator/scenario/report.hpp"

namespace canfleet::fleet {

void Fleet::WatchScenario() {
  runner_ = std::make_unique<scenario::ScenarioRunner>(
      scheduler_, options_.topology, *this,
      scenario::ScenarioRunner::Hooks{
          .act = [this](const topology::Step& step) { RunStep(step); },
          .decided =
              [this](const scenario::Result& result) {
                // The same line `canfleet test` prints and telemetry's Verdict carries.
                const std::string line = "expect " + ResultLine(result);
                if (result.verdict.outcome == scenario::Outcome::kPassed)
                  spdlog::info("{}", line);
                else
                  spdlog::warn("{}", line);
                for (const auto& handler : on_expectation_)
                  handler(result);
                ScenarioChanged();
              },
          .began = [this](int) { ScenarioChanged(); },
          .done =
              [this] {
                if (runner_->Expectations() > 0)
                  spdlog::info("scenario: every step ran, every expectation decided");
                ScenarioChanged();
                if (on_scenario_done_) on_scenario_done_();
                RepeatScenario();
              },
      });
  if (runner_->Expectations() == 0) return;
  for (const auto& bus : broker_.Buses())
    scenario_taps_.push_back(std::make_unique<ScenarioTap>(broker_, bus, *runner_));
}

void Fleet::StartScenario() {
  if (!options_.topology.scenario().empty())
    spdlog::info("scenario{}: {} step(s), {} expectation(s)",
                 scenario_run_ > 1 ? " run " + std::to_string(scenario_run_) : "",
                 options_.topology.scenario_size(), runner_->Expectations());
  runner_->Start();
  ScenarioChanged();
}

void Fleet::ScenarioChanged() {
  for (const auto& handler : on_scenario_change_)
    handler();
}

int Fleet::StepLine(int step) const {
  return step >= 0 && step < static_cast<int>(options_.step_lines.size())
             ? options_.step_lines[static_cast<std::size_t>(step)]
             : 0;
}

std::string Fleet::ResultLine(const scenario::Result& result) const {
  return scenario::ResultLine(ScenarioSource(), StepLine(result.step), result);
}

ScenarioNow Fleet::Scenario() const {
  ScenarioNow now;
  now.now = scheduler_.Now();
  if (!runner_) return now;
  now.progress = runner_->GetProgress();
  now.origin = runner_->origin();
  now.cycle = now.progress.started ? scenario_run_ : 0;
  return now;
}

void Fleet::RepeatScenario() {
  const auto pause = std::chrono::milliseconds(options_.topology.scenario_repeat_ms());
  if (!options_.repeat_scenario || pause.count() == 0 || options_.topology.scenario().empty()) return;
  spdlog::info("scenario: runs again in {:.1f} s", std::chrono::duration<double>(pause).count());
  // A fresh runner, not a rewound one: every window, anchor and verdict starts over. The old
  // runner is destroyed by the timer, never inside its own done hook (which runs in it).
  // One timer, re-armed: a run that ends as it starts re-arms it inside its own callback, which a
  // Timer allows (replacing it there would not be).
  if (!repeat_timer_)
    repeat_timer_ = std::make_unique<Timer>(scheduler_, [this] {
      scenario_taps_.clear();
      runner_.reset();
      ++scenario_run_;
      WatchScenario();
      StartScenario();
    });
  repeat_timer_->StartAfter(pause);
}

void Fleet::RunStep(const topology::Step& step) {
  const double t = step.at_ms() / 1000.0;
  try {
    switch (step.action_case()) {
      case topology::Step::kInject:
        faults_->Inject(step.inject());
        break;
      case topology::Step::kClear:
        faults_->Clear(step.clear());
        break;
      case topology::Step::kIo: {
        wire::NodeRequest request;
        request.mutable_io_set()->set_name(step.io().name());
        request.mutable_io_set()->set_value(step.io().value());
        IoRequest(step.io().node(), request, [t, step](const IoAnswer& answer) {
          if (!answer.error.empty())
            spdlog::error("scenario t={}s: io {} {}: {}", t, step.io().node(), step.io().name(),
                          answer.error);
          else if (!answer.notice.empty())
            spdlog::warn("scenario t={}s: io {}: {}", t, step.io().node(), answer.notice);
        });
        break;
      }
      case topology::Step::kNmt:
        spdlog::info("scenario t={}s: {}", t, Nmt(step.nmt()));
        break;
      case topology::Step::kSdo:
        SdoWrite(step.sdo(), [t](const std::string& error) {
          if (!error.empty()) spdlog::error("scenario t={}s: sdo write: {}", t, error);
        });
        break;
      default:
        break;
    }
  } catch (const std::exception& e) {
    spdlog::error("scenario t={}s: {}", t, e.what());
  }
}

void Fleet::ReadSdo(const scenario::PortAddress& port, std::size_t port_index, std::uint16_t index,
                    std::uint8_t subindex, SdoDone done) {
  (void)port_index;  // the address says which bus and node-ID
  sdo_.at(port.bus)->Read(port.node_id, index, subindex, false,
                          [done](canopen::SdoAbort abort, canopen::Bytes data) {
                            if (abort != canopen::SdoAbort::kNone)
                              return done(static_cast<std::uint32_t>(abort), {}, {});
                            done(std::nullopt, std::vector<std::uint8_t>(data.begin(), data.end()), {});
                          });
}

void Fleet::ReadIo(const std::string& node, const std::string& name, IoDone done) {
  wire::NodeRequest request;
  request.mutable_io_get()->set_name(name);
  try {
    IoRequest(node, request, [done, name](const IoAnswer& answer) {
      if (!answer.error.empty()) return done(answer.error, {}, {});
      for (const auto& v : answer.values.values())
        if (v.name() == name) return done({}, v.value(), v.unit());
      done("no signal " + name + " in the node's answer", {}, {});
    });
  } catch (const std::exception& e) {
    done(e.what(), {}, {});
  }
}

std::string Fleet::NmtState(const scenario::PortAddress& port) const {
  const NodeLiveState* live = tracker_.Find(port.bus, port.node_id);
  return NmtStateName(live ? live->nmt_state : std::nullopt);
}

std::string Fleet::ControllerState(const scenario::PortAddress& port) const {
  std::string state;
  for (const auto& p : broker_.Ports(port.bus)) {
    if (p.name != port.node) continue;  // the newest attachment of a name wins
    state = p.controller.state == ControllerState::kBusOff         ? "bus-off"
            : p.controller.state == ControllerState::kErrorPassive ? "error-passive"
                                                                   : "error-active";
  }
  return state;
}

double Fleet::LoadPercent(const std::string& bus) const {
  return broker_.Stats(bus, 0).load_percent;
}

namespace {

std::uint16_t Count16(std::size_t n) {
  return static_cast<std::uint16_t>(std::min<std::size_t>(n, UINT16_MAX));
}

double SecondsSince(std::optional<TimePoint> origin, TimePoint t) {
  return origin ? std::chrono::duration<double>(t - *origin).count() : 0.0;
}

telemetry::VerdictResult ToTelemetry(scenario::Outcome outcome) {
  switch (outcome) {
    case scenario::Outcome::kPassed:
      return telemetry::VerdictResult::kPass;
    case scenario::Outcome::kFailed:
      return telemetry::VerdictResult::kFail;
    default:
      return telemetry::VerdictResult::kSkip;
  }
}

}  // namespace

std::unique_ptr<broker::ScenarioTelemetry> PublishScenario(Fleet& fleet,
                                                           telemetry::OrchestratorTelemetry& publisher,
                                                           Scheduler& scheduler) {
  if (!fleet.HasScenario()) return nullptr;
  auto sample = [&fleet] {
    const ScenarioNow now = fleet.Scenario();
    const scenario::Progress& p = now.progress;
    telemetry::ScenarioStatusSnapshot s;
    s.source = fleet.ScenarioSource();
    s.scenario = fleet.TopologyName();
    s.time_mode = fleet.VirtualTime() ? "virtual" : "real";
    s.scenario_time_s = SecondsSince(now.origin, now.now);
    s.cycle = static_cast<std::uint32_t>(std::max(now.cycle, 0));
    s.running = p.started && !p.done;
    s.expectations = Count16(p.expectations);
    s.passed = Count16(p.passed);
    s.failed = Count16(p.failed);
    s.skipped = Count16(p.skipped);
    s.pending = Count16(p.pending);
    s.step = p.step;
    s.step_time_s = p.step_time ? SecondsSince(now.origin, *p.step_time) : 0.0;
    return s;
  };
  auto published = std::make_unique<broker::ScenarioTelemetry>(scheduler, publisher, std::move(sample));
  broker::ScenarioTelemetry* telemetry = published.get();
  fleet.OnScenarioChange([telemetry] { telemetry->Sample(); });
  fleet.OnExpectation([&fleet, telemetry](const scenario::Result& result) {
    const ScenarioNow now = fleet.Scenario();
    telemetry->PublishVerdict({.source = fleet.ScenarioSource(),
                               .index = Count16(static_cast<std::size_t>(std::max(result.index, 0))),
                               .scenario = fleet.TopologyName(),
                               .cycle = static_cast<std::uint32_t>(std::max(now.cycle, 1)),
                               .result = ToTelemetry(result.verdict.outcome),
                               .name = result.name,
                               .line = static_cast<std::uint32_t>(std::max(fleet.StepLine(result.step), 0)),
                               .text = fleet.ResultLine(result),
                               .scenario_time_s = SecondsSince(now.origin, result.verdict.time)});
  });
  return published;
}

}  // namespace canfleet::fleet
