#include "tools/telemetry/fleet_view.hpp"

#include <algorithm>
#include <cstdio>
#include <iterator>

namespace canfleet::tools {

using telemetry::ControllerState;
using telemetry::FaultAction;
using telemetry::HeartbeatConsumerState;

const char* ToString(EventKind kind) {
  switch (kind) {
    case EventKind::kNodeSeen:
      return "seen";
    case EventKind::kNodeGone:
      return "gone";
    case EventKind::kNmt:
      return "nmt";
    case EventKind::kController:
      return "controller";
    case EventKind::kErrorRegister:
      return "error-register";
    case EventKind::kHeartbeatConsumer:
      return "hb-consumer";
    case EventKind::kEmcy:
      return "emcy";
    case EventKind::kFault:
      return "fault";
    case EventKind::kVerdict:
      return "verdict";
  }
  return "?";
}

std::optional<EventKind> ParseEventKind(std::string_view text) {
  for (auto kind : {EventKind::kNodeSeen, EventKind::kNodeGone, EventKind::kNmt, EventKind::kController,
                    EventKind::kErrorRegister, EventKind::kHeartbeatConsumer, EventKind::kEmcy,
                    EventKind::kFault, EventKind::kVerdict}) {
    if (text == ToString(kind)) return kind;
  }
  return std::nullopt;
}

namespace {

std::string Hex2(unsigned value) {
  char text[8];
  std::snprintf(text, sizeof text, "%02Xh", value & 0xFFu);
  return text;
}

}  // namespace

FleetView::FleetView(WallTime started, std::size_t recent_capacity)
    : started_(started), recent_capacity_(recent_capacity) {}

void FleetView::Emit(FleetEvent event, std::vector<FleetEvent>* events) {
  event.replay = event.time < started_;
  if (event.node_id != 0 && event.name.empty() && event.kind != EventKind::kVerdict) {
    if (const auto it = nodes_.find({event.bus, event.node_id}); it != nodes_.end())
      event.name = it->second.status.name;
  }
  // Samples of different topics arrive in batches per topic: keep the list in time order.
  auto at = recent_.end();
  while (at != recent_.begin() && std::prev(at)->time > event.time)
    --at;
  recent_.insert(at, event);
  while (recent_.size() > recent_capacity_)
    recent_.pop_front();
  if (events) events->push_back(std::move(event));
}

void FleetView::Apply(const NodeStatusSample& sample, const SampleMeta& meta,
                      std::vector<FleetEvent>* events) {
  if (meta.valid_data) ApplyStatus(sample, meta, events);
  // The instance state counts whether or not the sample carries data. A node's last status and its
  // dispose (or the loss of its writers) that reach the reader before it takes arrive as one valid
  // sample whose instance state is already NOT_ALIVE: Cyclone then queues no separate invalid
  // sample, and the instance is gone from the reader once taken. Looking only at invalid samples
  // kept such a node alive for ever (the flaky "node seen leaving" check of issue 7).
  if (!meta.alive) MarkGone(sample.key(), meta, events);
}

void FleetView::MarkGone(const NodeKey& key, const SampleMeta& meta, std::vector<FleetEvent>* events) {
  const auto it = nodes_.find(key);
  if (it == nodes_.end() || !it->second.alive) return;
  it->second.alive = false;
  it->second.disposed = meta.disposed;
  it->second.last_change = meta.source_time;
  Emit({.time = meta.source_time,
        .kind = EventKind::kNodeGone,
        .bus = key.bus,
        .node_id = key.node_id,
        .from = "",
        .to = meta.disposed ? "disposed" : "no-writers"},
       events);
}

void FleetView::ApplyStatus(const NodeStatusSample& sample, const SampleMeta& meta,
                            std::vector<FleetEvent>* events) {
  const NodeKey key = sample.key();
  auto it = nodes_.find(key);
  if (it == nodes_.end()) {
    NodeRow row;
    row.status = sample;
    row.last_sample = meta.source_time;
    row.last_change = meta.source_time;
    if (auto early = early_emcy_.find(key); early != early_emcy_.end()) {
      row.emcy_history = std::move(early->second);
      row.last_emcy = row.emcy_history.back().sample;
      row.last_emcy_time = row.emcy_history.back().time;
      early_emcy_.erase(early);
    }
    nodes_.emplace(key, std::move(row));
    // Events of the node that came before its first status (an EMCY is taken before the status
    // it changed) get its name now.
    if (!sample.name.empty()) {
      for (FleetEvent& e : recent_)
        if (e.name.empty() && e.kind != EventKind::kVerdict && e.node_id == key.node_id && e.bus == key.bus)
          e.name = sample.name;
    }
    last_new_node_ = std::max(last_new_node_, std::chrono::system_clock::now());
    Emit({.time = meta.source_time,
          .kind = EventKind::kNodeSeen,
          .bus = key.bus,
          .node_id = key.node_id,
          .from = "",
          .to = telemetry::StateName(sample.nmt_state)},
         events);
    return;
  }
  NodeRow& row = it->second;
  const NodeStatusSample& old = row.status;
  const auto event = [&](EventKind kind, std::string from, std::string to) {
    row.last_change = meta.source_time;
    Emit({.time = meta.source_time,
          .kind = kind,
          .bus = key.bus,
          .node_id = key.node_id,
          .from = std::move(from),
          .to = std::move(to)},
         events);
  };
  if (!row.alive) event(EventKind::kNodeSeen, "gone", telemetry::StateName(sample.nmt_state));
  if (old.nmt_state != sample.nmt_state) {
    event(EventKind::kNmt, telemetry::StateName(old.nmt_state), telemetry::StateName(sample.nmt_state));
  }
  if (old.controller_state != sample.controller_state) {
    event(EventKind::kController, telemetry::StateName(old.controller_state),
          telemetry::StateName(sample.controller_state));
  }
  if (old.error_register != sample.error_register) {
    event(EventKind::kErrorRegister, Hex2(old.error_register), Hex2(sample.error_register));
  }
  for (const auto& consumer : sample.heartbeat_consumers) {
    const auto previous = std::find_if(old.heartbeat_consumers.begin(), old.heartbeat_consumers.end(),
                                       [&](const auto& c) { return c.node_id == consumer.node_id; });
    const HeartbeatConsumerState before =
        previous == old.heartbeat_consumers.end() ? HeartbeatConsumerState::kUnknown : previous->state;
    if (before != consumer.state) {
      row.last_change = meta.source_time;
      Emit({.time = meta.source_time,
            .kind = EventKind::kHeartbeatConsumer,
            .bus = key.bus,
            .node_id = key.node_id,
            .from = telemetry::ToString(before),
            .to = telemetry::ToString(consumer.state),
            .peer_node = consumer.node_id},
           events);
    }
  }
  row.status = sample;
  row.alive = true;
  row.disposed = false;
  row.last_sample = meta.source_time;
}

void FleetView::Apply(const EmcySample& sample, const SampleMeta& meta, std::vector<FleetEvent>* events) {
  if (!meta.valid_data) return;
  auto it = nodes_.find({sample.bus, sample.node_id});
  std::deque<EmcyRecord>& history =
      it != nodes_.end() ? it->second.emcy_history : early_emcy_[NodeKey{sample.bus, sample.node_id}];
  // Topics arrive in batches: keep the history in time order, like recent().
  auto at = history.end();
  while (at != history.begin() && std::prev(at)->time > meta.source_time)
    --at;
  history.insert(at, EmcyRecord{sample, meta.source_time});
  while (history.size() > kEmcyHistory)
    history.pop_front();
  if (it != nodes_.end()) {
    it->second.last_emcy = sample;
    it->second.last_emcy_time = meta.source_time;
  }
  Emit({.time = meta.source_time,
        .kind = EventKind::kEmcy,
        .bus = sample.bus,
        .node_id = sample.node_id,
        .emcy = sample},
       events);
}

void FleetView::Apply(const IoSnapshotSample& sample, const SampleMeta& meta, std::vector<FleetEvent>*) {
  auto it = nodes_.find({sample.bus, sample.node_id});
  if (it == nodes_.end()) return;  // I/O is shown with its node; the status arrives within a period
  if (meta.valid_data && meta.alive) {
    it->second.io = sample;
  } else {  // disposed or without writers, with or without data (see the NodeStatus Apply)
    it->second.io.reset();
  }
}

void FleetView::Apply(const BusStatsSample& sample, const SampleMeta& meta, std::vector<FleetEvent>*) {
  if (!meta.valid_data || !meta.alive) {  // the bus was removed or its publisher left
    buses_[sample.bus].stats.reset();
    return;
  }
  buses_[sample.bus].stats = sample;
}

void FleetView::Apply(const FaultEventSample& sample, const SampleMeta& meta,
                      std::vector<FleetEvent>* events) {
  if (!meta.valid_data) return;
  BusRow& bus = buses_[sample.bus];
  if (sample.action == FaultAction::kInjected) {
    bus.active_faults[sample.fault_id] = sample;
  } else {
    bus.active_faults.erase(sample.fault_id);
  }
  Emit({.time = meta.source_time,
        .kind = EventKind::kFault,
        .bus = sample.bus,
        .node_id = sample.target_node,
        .fault = sample},
       events);
}

void FleetView::Apply(const VerdictSample& sample, const SampleMeta& meta, std::vector<FleetEvent>* events) {
  // A dispose (the fleet stopped) carries no verdict: only samples with data are events.
  if (!meta.valid_data) return;
  Emit({.time = meta.source_time, .kind = EventKind::kVerdict, .verdict = sample}, events);
}

void FleetView::Apply(const ScenarioStatusSample& sample, const SampleMeta& meta, std::vector<FleetEvent>*) {
  if (meta.valid_data) {
    ScenarioRow& row = scenarios_[sample.source];
    row.status = sample;
    row.alive = meta.alive;
    row.last_sample = meta.source_time;
  } else if (const auto it = scenarios_.find(sample.source); it != scenarios_.end()) {
    it->second.alive = meta.alive;
  }
  // A scenario whose fleet stopped says nothing any more: it is dropped, like a removed bus.
  if (!meta.alive) scenarios_.erase(sample.source);
}

bool IsStale(const ScenarioRow& row, WallTime now) {
  const auto period = std::max<std::chrono::milliseconds>(row.status.publish_period, std::chrono::seconds(1));
  return now - row.last_sample > 3 * period;
}

bool IsStale(const NodeRow& row, WallTime now) {
  const auto period = std::max<std::chrono::milliseconds>(row.status.publish_period, std::chrono::seconds(1));
  return row.alive && now - row.last_sample > 3 * period;
}

bool IsFaulted(const NodeRow& row, WallTime now) {
  if (!row.alive || IsStale(row, now)) return true;
  const auto& s = row.status;
  if (s.controller_state == ControllerState::kBusOff || s.error_register != 0) return true;
  return std::any_of(s.heartbeat_consumers.begin(), s.heartbeat_consumers.end(),
                     [](const auto& c) { return c.state == HeartbeatConsumerState::kTimedOut; });
}

}  // namespace canfleet::tools
