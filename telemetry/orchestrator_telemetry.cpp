#include "telemetry/orchestrator_telemetry.hpp"

#include <algorithm>
#include <atomic>
#include <deque>
#include <map>
#include <stdexcept>

#include "telemetry/samples.hpp"
#include "telemetry/topics.hpp"

namespace canfleet::telemetry {

bool BusStatsChanged(const BusStatsSnapshot& a, const BusStatsSnapshot& b) {
  return a.bitrate != b.bitrate || a.mode != b.mode || a.node_count != b.node_count ||
         a.error_frames != b.error_frames;
}

bool ScenarioStatusChanged(const ScenarioStatusSnapshot& a, const ScenarioStatusSnapshot& b) {
  return a.scenario != b.scenario || a.time_mode != b.time_mode || a.cycle != b.cycle ||
         a.running != b.running || a.expectations != b.expectations || a.passed != b.passed ||
         a.failed != b.failed || a.skipped != b.skipped || a.pending != b.pending || a.step != b.step ||
         a.step_time_s != b.step_time_s;
}

std::string SourceKey(const std::string& source) {
  if (source.size() <= kMaxScenarioSource) return source;
  return std::string(kCutMarker) + source.substr(source.size() - (kMaxScenarioSource - kCutMarker.size()));
}

namespace {

void CheckBusName(const std::string& bus) {
  if (bus.empty() || bus.size() > kMaxBusName) {
    throw std::invalid_argument("bus name '" + bus + "' must have 1.." + std::to_string(kMaxBusName) +
                                " characters");
  }
}

/// Publisher-thread state of one bus.
struct BusState {
  BusStatsSnapshot current;
  BusStatsSnapshot published;
  bool change = true;
  bool removed = false;
  TimePoint written{};
  TimePoint due{};
  std::uint32_t serial = 0;
};

/// Publisher-thread state of one scenario.
struct ScenarioState {
  ScenarioStatusSnapshot current;
  ScenarioStatusSnapshot published;
  bool change = true;
  bool removed = false;
  TimePoint written{};
  TimePoint due{};
  std::uint32_t serial = 0;
};

}  // namespace

struct OrchestratorTelemetry::Impl {
  explicit Impl(const Participant& participant, OrchestratorTelemetryOptions opts)
      : options(opts),
        stats_topic(participant),
        fault_topic(participant),
        stats_writer(participant, stats_topic),
        fault_writer(participant, fault_topic),
        verdict_topic(participant),
        scenario_topic(participant),
        verdict_writer(participant, verdict_topic),
        scenario_writer(participant, scenario_topic) {
    stats_sample.top_cob_ids = {static_cast<std::uint32_t>(cob_ids.size()), 0, cob_ids.data(), false};
    fault_sample.parameters = {static_cast<std::uint32_t>(parameters.size()), 0, parameters.data(), false};
  }

  const OrchestratorTelemetryOptions options;
  Topic<canfleet_telemetry_BusStats> stats_topic;
  Topic<canfleet_telemetry_FaultEvent> fault_topic;
  Writer<canfleet_telemetry_BusStats> stats_writer;
  Writer<canfleet_telemetry_FaultEvent> fault_writer;
  Topic<canfleet_telemetry_Verdict> verdict_topic;
  Topic<canfleet_telemetry_ScenarioStatus> scenario_topic;
  Writer<canfleet_telemetry_Verdict> verdict_writer;
  Writer<canfleet_telemetry_ScenarioStatus> scenario_writer;

  // Guarded by PublisherLoop::mutex().
  std::map<std::string, BusStatsSnapshot, std::less<>> pending;
  std::vector<std::string> pending_removals;
  std::deque<FaultSnapshot> faults;
  std::deque<VerdictSnapshot> verdicts;
  std::map<std::string, ScenarioStatusSnapshot, std::less<>> pending_scenarios;
  std::vector<std::string> pending_scenario_removals;

  // Publisher thread.
  std::map<std::string, BusState, std::less<>> buses;
  std::vector<FaultSnapshot> fault_batch;
  std::vector<VerdictSnapshot> verdict_batch;
  std::map<std::string, std::uint32_t, std::less<>> fault_serials;
  std::map<std::string, std::uint32_t, std::less<>> verdict_serials;
  std::map<std::string, ScenarioState, std::less<>> scenarios;
  canfleet_telemetry_Verdict verdict_sample{};
  canfleet_telemetry_ScenarioStatus scenario_sample{};
  canfleet_telemetry_BusStats stats_sample{};
  std::array<canfleet_telemetry_CobIdRate, kMaxTopCobIds> cob_ids{};
  canfleet_telemetry_FaultEvent fault_sample{};
  std::array<canfleet_telemetry_FaultParameter, kMaxFaultParameters> parameters{};

  std::atomic<std::uint64_t> state_writes{0};
  std::atomic<std::uint64_t> event_writes{0};
  std::atomic<std::uint64_t> write_errors{0};
  std::atomic<std::uint64_t> events_dropped{0};

  void Count(dds_return_t rc, std::atomic<std::uint64_t>& ok) {
    (rc == DDS_RETCODE_OK ? ok : write_errors).fetch_add(1, std::memory_order_relaxed);
  }

  void WriteStats(BusState& bus) {
    const BusStatsSnapshot& s = bus.current;
    CopyBounded(stats_sample.bus, s.bus);
    stats_sample.bitrate = s.bitrate;
    CopyBounded(stats_sample.mode, s.mode);
    stats_sample.load_percent = s.load_percent;
    stats_sample.frames_per_second = s.frames_per_second;
    stats_sample.frames_total = s.frames_total;
    stats_sample.error_frames = s.error_frames;
    stats_sample.node_count = s.node_count;
    const std::size_t n = std::min<std::size_t>(s.top_cob_id_count, kMaxTopCobIds);
    for (std::size_t i = 0; i < n; ++i)
      cob_ids[i] = {s.top_cob_ids[i].cob_id, s.top_cob_ids[i].frames_per_second};
    stats_sample.top_cob_ids._length = static_cast<std::uint32_t>(n);
    stats_sample.serial = ++bus.serial;
    stats_sample.simulated_s = s.simulated_s;
    stats_sample.speed_factor = s.speed_factor;
    Count(stats_writer.Write(stats_sample), state_writes);
  }

  void WriteFault(const FaultSnapshot& f) {
    CopyBounded(fault_sample.bus, f.bus);
    fault_sample.fault_id = f.fault_id;
    fault_sample.action = ToDds(f.action);
    CopyBounded(fault_sample.kind, f.kind);
    fault_sample.target_node = f.target_node;
    const std::size_t n = std::min(f.parameters.size(), kMaxFaultParameters);
    for (std::size_t i = 0; i < n; ++i) {
      CopyBounded(parameters[i].name, f.parameters[i].first);
      CopyBoundedAtWord(parameters[i].value, f.parameters[i].second);
    }
    fault_sample.parameters._length = static_cast<std::uint32_t>(n);
    fault_sample.bus_time_ns = static_cast<std::uint64_t>(f.bus_time.count());
    fault_sample.serial = ++fault_serials[f.bus];
    Count(fault_writer.Write(fault_sample), event_writes);
  }

  void WriteVerdict(const VerdictSnapshot& v) {
    const std::string key = SourceKey(v.source);
    CopyBounded(verdict_sample.source, key);
    verdict_sample.index = v.index;
    CopyBoundedAtWord(verdict_sample.scenario, v.scenario);
    verdict_sample.cycle = v.cycle;
    verdict_sample.result = ToDds(v.result);
    CopyBoundedAtWord(verdict_sample.name, v.name);
    verdict_sample.line = v.line;
    verdict_sample.text_cut = CopyBoundedAtWord(verdict_sample.text, v.text);
    verdict_sample.scenario_time_s = v.scenario_time_s;
    verdict_sample.serial = ++verdict_serials[key];
    Count(verdict_writer.Write(verdict_sample), event_writes);
  }

  void WriteScenario(const std::string& key, ScenarioState& state) {
    const ScenarioStatusSnapshot& s = state.current;
    CopyBounded(scenario_sample.source, key);
    CopyBoundedAtWord(scenario_sample.scenario, s.scenario);
    CopyBounded(scenario_sample.time_mode, s.time_mode);
    scenario_sample.scenario_time_s = s.scenario_time_s;
    scenario_sample.cycle = s.cycle;
    scenario_sample.running = s.running;
    scenario_sample.expectations = s.expectations;
    scenario_sample.passed = s.passed;
    scenario_sample.failed = s.failed;
    scenario_sample.skipped = s.skipped;
    scenario_sample.pending = s.pending;
    CopyBoundedAtWord(scenario_sample.step, s.step);
    scenario_sample.step_time_s = s.step_time_s;
    scenario_sample.publish_period_ms = static_cast<std::uint32_t>(options.period.count());
    scenario_sample.serial = ++state.serial;
    Count(scenario_writer.Write(scenario_sample), state_writes);
  }
};

OrchestratorTelemetry::OrchestratorTelemetry(const Participant& participant,
                                             OrchestratorTelemetryOptions options)
    : PublisherLoop(options.min_interval) {
  Init(participant, options);
}

OrchestratorTelemetry::OrchestratorTelemetry(const Participant& participant,
                                             OrchestratorTelemetryOptions options, Scheduler& scheduler)
    : PublisherLoop(options.min_interval, scheduler) {
  Init(participant, options);
}

void OrchestratorTelemetry::Init(const Participant& participant, OrchestratorTelemetryOptions options) {
  if (options.period <= std::chrono::milliseconds::zero()) throw std::invalid_argument("period must be > 0");
  impl_ = std::make_unique<Impl>(participant, options);
  Start();
}

OrchestratorTelemetry::~OrchestratorTelemetry() {
  Stop();
}

void OrchestratorTelemetry::UpdateBusStats(const BusStatsSnapshot& stats) {
  CheckBusName(stats.bus);
  bool notify;
  {
    const std::lock_guard lock(mutex());
    auto it = impl_->pending.find(stats.bus);
    if (it == impl_->pending.end()) {
      impl_->pending.emplace(stats.bus, stats);
    } else {
      it->second = stats;
    }
    notify = MarkInputLocked();
  }
  if (notify) Notify();
}

void OrchestratorTelemetry::RemoveBus(const std::string& bus) {
  bool notify;
  {
    const std::lock_guard lock(mutex());
    impl_->pending.erase(bus);
    impl_->pending_removals.push_back(bus);
    notify = MarkEventLocked();
  }
  if (notify) Notify();
}

void OrchestratorTelemetry::PublishFault(FaultSnapshot fault) {
  CheckBusName(fault.bus);
  bool notify = false;
  {
    const std::lock_guard lock(mutex());
    if (impl_->faults.size() >= impl_->options.fault_queue) {
      impl_->events_dropped.fetch_add(1, std::memory_order_relaxed);
    } else {
      impl_->faults.push_back(std::move(fault));
      notify = MarkEventLocked();
    }
  }
  if (notify) Notify();
}

void OrchestratorTelemetry::PublishVerdict(VerdictSnapshot verdict) {
  bool notify = false;
  {
    const std::lock_guard lock(mutex());
    if (impl_->faults.size() + impl_->verdicts.size() >= impl_->options.fault_queue) {
      impl_->events_dropped.fetch_add(1, std::memory_order_relaxed);
    } else {
      impl_->verdicts.push_back(std::move(verdict));
      notify = MarkEventLocked();
    }
  }
  if (notify) Notify();
}

void OrchestratorTelemetry::UpdateScenario(const ScenarioStatusSnapshot& status) {
  const std::string key = SourceKey(status.source);
  bool notify;
  {
    const std::lock_guard lock(mutex());
    impl_->pending_scenarios[key] = status;
    notify = MarkInputLocked();
  }
  if (notify) Notify();
}

void OrchestratorTelemetry::RemoveScenario(const std::string& source) {
  const std::string key = SourceKey(source);
  bool notify;
  {
    const std::lock_guard lock(mutex());
    impl_->pending_scenarios.erase(key);
    impl_->pending_scenario_removals.push_back(key);
    notify = MarkEventLocked();
  }
  if (notify) Notify();
}

PublisherStats OrchestratorTelemetry::stats() const {
  return {impl_->state_writes.load(), impl_->event_writes.load(), impl_->write_errors.load(),
          impl_->events_dropped.load()};
}

void OrchestratorTelemetry::ConsumeLocked(bool inputs) {
  Impl& m = *impl_;
  while (!m.faults.empty()) {
    m.fault_batch.push_back(std::move(m.faults.front()));
    m.faults.pop_front();
  }
  // A verdict's scenario status (handed over just before it) goes out with it, not after the
  // sampling window: a reader sees the counts that include the verdict.
  const bool verdicts = !m.verdicts.empty();
  while (!m.verdicts.empty()) {
    m.verdict_batch.push_back(std::move(m.verdicts.front()));
    m.verdicts.pop_front();
  }
  for (const std::string& bus : m.pending_removals) {
    auto it = m.buses.find(bus);
    if (it != m.buses.end()) it->second.removed = true;
  }
  m.pending_removals.clear();
  for (const std::string& source : m.pending_scenario_removals) {
    auto it = m.scenarios.find(source);
    if (it != m.scenarios.end()) it->second.removed = true;
  }
  m.pending_scenario_removals.clear();
  if (inputs || verdicts) {
    for (auto& [source, snapshot] : m.pending_scenarios) {
      ScenarioState& scenario = m.scenarios[source];
      scenario.current = snapshot;
      scenario.removed = false;
    }
    m.pending_scenarios.clear();
  }
  if (!inputs) return;
  for (auto& [name, snapshot] : m.pending) {
    BusState& bus = m.buses[name];
    bus.current = snapshot;
    bus.removed = false;
  }
  m.pending.clear();
}

TimePoint OrchestratorTelemetry::Publish(TimePoint now, bool force) {
  Impl& m = *impl_;
  for (const FaultSnapshot& f : m.fault_batch)
    m.WriteFault(f);
  m.fault_batch.clear();
  // The scenario's status before its verdicts: a reader that shows a verdict finds its cycle.
  TimePoint next = now + m.options.period;
  for (auto it = m.scenarios.begin(); it != m.scenarios.end();) {
    ScenarioState& scenario = it->second;
    if (scenario.removed) {
      canfleet_telemetry_ScenarioStatus key{};
      CopyBounded(key.source, it->first);
      m.scenario_writer.Dispose(key);
      it = m.scenarios.erase(it);
      continue;
    }
    scenario.change = scenario.change || ScenarioStatusChanged(scenario.current, scenario.published);
    if (now >= scenario.due || (scenario.change && (force || now >= scenario.written + min_interval() ||
                                                    !m.verdict_batch.empty()))) {
      m.WriteScenario(it->first, scenario);
      scenario.published = scenario.current;
      scenario.change = false;
      scenario.written = now;
      scenario.due = now + m.options.period;
    }
    next = std::min(next, scenario.due);
    if (scenario.change) next = std::min(next, scenario.written + min_interval());
    ++it;
  }
  for (const VerdictSnapshot& v : m.verdict_batch)
    m.WriteVerdict(v);
  m.verdict_batch.clear();

  for (auto it = m.buses.begin(); it != m.buses.end();) {
    BusState& bus = it->second;
    if (bus.removed) {
      canfleet_telemetry_BusStats key{};
      CopyBounded(key.bus, it->first);
      m.stats_writer.Dispose(key);
      it = m.buses.erase(it);
      continue;
    }
    bus.change = bus.change || BusStatsChanged(bus.current, bus.published);
    if (now >= bus.due || (bus.change && (force || now >= bus.written + min_interval()))) {
      m.WriteStats(bus);
      bus.published = bus.current;
      bus.change = false;
      bus.written = now;
      bus.due = now + m.options.period;
    }
    next = std::min(next, bus.due);
    if (bus.change) next = std::min(next, bus.written + min_interval());
    ++it;
  }
  return next;
}

}  // namespace canfleet::telemetry
