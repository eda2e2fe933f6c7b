#include "node/canopen/heartbeat/heartbeat_consumer.hpp"

#include <chrono>

#include "node/canopen/nmt/error_control.hpp"

namespace canfleet::canopen {

using State = HeartbeatConsumerStatus::State;

struct HeartbeatConsumer::Entry {
  Entry(Scheduler& scheduler, HeartbeatConsumer& owner, std::uint8_t sub)
      : sub_index(sub), timer(scheduler, [this, &owner] { owner.OnTimeout(*this); }) {}

  std::uint8_t sub_index;
  std::uint8_t node_id = 0;
  Duration period{};
  State state = State::kUnconfigured;
  NmtState last_state = NmtState::kInitialising;
  Timer timer;
};

namespace {

struct EntryConfig {
  std::uint8_t node_id;
  std::uint16_t time_ms;
  bool Active() const { return IsValidNodeId(node_id) && time_ms != 0; }
};

EntryConfig Decode(std::uint64_t raw) {
  return {static_cast<std::uint8_t>(raw >> 16), static_cast<std::uint16_t>(raw)};
}

}  // namespace

HeartbeatConsumer::HeartbeatConsumer(ObjectDictionary& od, Scheduler& scheduler, CommErrorSink& errors)
    : od_(od), errors_(errors) {
  Object* obj = od_.Find(kConsumerHeartbeatTimeIndex);
  if (!obj) return;
  for (auto& [sub_index, sub] : obj->subs) {
    if (sub_index == 0) {
      // CiA 301 §7.5.2.19: sub0 is the number of entries, read-only even if an EDS says rw.
      sub.AddValidator(
          [](const SubObject&, std::span<const std::uint8_t>, Origin) { return SdoAbort::kReadOnly; });
      continue;
    }
    entries_.push_back(std::make_unique<Entry>(scheduler, *this, sub_index));
    sub.AddValidator([this](const SubObject& s, std::span<const std::uint8_t> data, Origin) {
      return Validate(s.sub_index, data);
    });
    sub.AddListener([this](SubObject& s, Origin) { Apply(s.sub_index, false); });
  }
  Apply(0, true);
}

HeartbeatConsumer::~HeartbeatConsumer() = default;

SdoAbort HeartbeatConsumer::Validate(std::uint8_t sub_index, std::span<const std::uint8_t> data) const {
  EntryConfig wanted = Decode(DecodeUnsignedLe(data));
  if (!wanted.Active()) return SdoAbort::kNone;
  // CiA 301 §7.5.2.19: at most one active entry per producer node-ID (CANopenNode answers
  // 06040043h, general parameter incompatibility).
  for (const auto& entry : entries_) {
    if (entry->sub_index == sub_index) continue;
    EntryConfig other = Decode(od_.GetUnsigned(kConsumerHeartbeatTimeIndex, entry->sub_index));
    if (other.Active() && other.node_id == wanted.node_id) return SdoAbort::kParameterIncompatible;
  }
  return SdoAbort::kNone;
}

void HeartbeatConsumer::Apply(std::uint8_t restart_sub, bool restart_all) {
  // Re-derives every entry from the OD. Only entries whose configuration changed (or that were
  // written) restart, so writing one entry does not disturb the monitoring of the others.
  for (std::size_t i = 0; i < entries_.size(); ++i) {
    Entry& entry = *entries_[i];
    EntryConfig config = Decode(od_.GetUnsigned(kConsumerHeartbeatTimeIndex, entry.sub_index));
    bool active = config.Active();
    // The device itself bypasses the validator: a duplicate node-ID is then left to the first entry.
    for (std::size_t j = 0; active && j < i; ++j) {
      const Entry& earlier = *entries_[j];
      if (earlier.state != State::kUnconfigured && earlier.node_id == config.node_id) active = false;
    }
    Duration period = std::chrono::milliseconds(config.time_ms);
    bool changed = active != (entry.state != State::kUnconfigured) || config.node_id != entry.node_id ||
                   period != entry.period;
    if (!changed && !restart_all && entry.sub_index != restart_sub) continue;
    StopMonitoring(entry);
    entry.node_id = config.node_id;
    entry.period = period;
    entry.state = active ? State::kWaiting : State::kUnconfigured;
    entry.last_state = NmtState::kInitialising;
  }
}

void HeartbeatConsumer::Reset() {
  Apply(0, true);
}

void HeartbeatConsumer::StopMonitoring(Entry& entry) {
  entry.timer.Cancel();
  if (entry.state == State::kTimedOut) {
    entry.state = State::kWaiting;
    errors_.OnCommError({CommErrorKind::kHeartbeatTimeout, entry.node_id}, false);
  }
}

void HeartbeatConsumer::AddListenedIds(std::vector<std::uint32_t>& ids) const {
  for (const auto& entry : entries_)
    if (entry->state != State::kUnconfigured) ids.push_back(kErrorControlCobId + entry->node_id);
}

void HeartbeatConsumer::AddPassiveIds(std::vector<std::pair<std::uint32_t, Duration>>& out) const {
  // Receive: a heartbeat (not a boot-up) from a producer that is not timed out only records its
  // state and re-arms the timeout, `period` from its arrival; nothing is sent at once.
  for (const auto& entry : entries_)
    if (entry->state == State::kWaiting || entry->state == State::kActive)
      out.emplace_back(kErrorControlCobId + entry->node_id, entry->period);
}

bool HeartbeatConsumer::OnFrame(const CanFrame& frame) {
  if (frame.extended() || frame.remote() || frame.error()) return false;
  if (frame.id <= kErrorControlCobId || frame.id > kErrorControlCobId + 127 || frame.dlc != 1) return false;
  const auto node_id = static_cast<std::uint8_t>(frame.id - kErrorControlCobId);
  for (auto& entry : entries_) {
    if (entry->state != State::kUnconfigured && entry->node_id == node_id) Receive(*entry, frame.data[0]);
  }
  return false;
}

void HeartbeatConsumer::Receive(Entry& entry, std::uint8_t state_byte) {
  // State changes are committed before reporting: the sink may react (1029h) synchronously.
  if (state_byte == static_cast<std::uint8_t>(NmtState::kInitialising)) {
    entry.last_state = NmtState::kInitialising;
    // CiA 301 §7.2.8.3.2.2: only heartbeats start monitoring; a boot-up while waiting is no event.
    if (entry.state == State::kWaiting) return;
    entry.timer.Cancel();
    const bool timed_out = entry.state == State::kTimedOut;
    entry.state = State::kWaiting;
    const CommError timeout{CommErrorKind::kHeartbeatTimeout, entry.node_id};
    const CommError boot_up{CommErrorKind::kBootUpOfMonitored, entry.node_id};
    if (timed_out) errors_.OnCommError(timeout, false);
    // The producer was reset (CANopenNode: CO_EM_HB_CONSUMER_REMOTE_RESET); an event, not a condition.
    errors_.OnCommError(boot_up, true);
    errors_.OnCommError(boot_up, false);
    return;
  }
  entry.last_state = static_cast<NmtState>(state_byte);
  const bool timed_out = entry.state == State::kTimedOut;
  entry.state = State::kActive;
  entry.timer.StartAfter(entry.period);
  if (timed_out) errors_.OnCommError({CommErrorKind::kHeartbeatTimeout, entry.node_id}, false);
}

void HeartbeatConsumer::OnTimeout(Entry& entry) {
  if (entry.state != State::kActive) return;
  entry.state = State::kTimedOut;
  errors_.OnCommError({CommErrorKind::kHeartbeatTimeout, entry.node_id}, true);
}

std::vector<HeartbeatConsumerStatus> HeartbeatConsumer::Status() const {
  std::vector<HeartbeatConsumerStatus> out;
  out.reserve(entries_.size());
  for (const auto& entry : entries_) {
    out.push_back({entry->node_id, entry->period, entry->state, entry->last_state, entry->sub_index});
  }
  return out;
}

}  // namespace canfleet::canopen
