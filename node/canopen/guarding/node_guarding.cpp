#include "node/canopen/guarding/node_guarding.hpp"

#include <chrono>
#include <utility>

#include "node/canopen/nmt/error_control.hpp"

namespace canfleet::canopen {

namespace {
constexpr std::uint16_t kProducerHeartbeatTime = 0x1017;
}  // namespace

NodeGuarding::NodeGuarding(ObjectDictionary& od, BusPort& port, Scheduler& scheduler, CommErrorSink& errors,
                           std::function<NmtState()> state)
    : od_(od), port_(port), errors_(errors), state_(std::move(state)), life_timer_(scheduler, [this] {
        OnLifeTimeExpired();
      }) {
  for (std::uint16_t index : {kGuardTimeIndex, kLifeTimeFactorIndex, kProducerHeartbeatTime}) {
    if (SubObject* sub = od_.Find(index, 0)) {
      sub->AddListener([this](SubObject&, Origin) { OnConfigChanged(); });
    }
  }
}

Duration NodeGuarding::LifeTime() const {
  if (!od_.Find(kGuardTimeIndex, 0) || !od_.Find(kLifeTimeFactorIndex, 0)) return Duration::zero();
  if (od_.GetUnsigned(kProducerHeartbeatTime, 0) != 0) return Duration::zero();
  const auto guard_time_ms = od_.GetUnsigned(kGuardTimeIndex, 0) & 0xFFFF;
  const auto factor = od_.GetUnsigned(kLifeTimeFactorIndex, 0) & 0xFF;
  return std::chrono::milliseconds(guard_time_ms * factor);
}

void NodeGuarding::AddListenedIds(std::vector<std::uint32_t>& ids) const {
  if (IsValidNodeId(node_id_)) ids.push_back(kErrorControlCobId + node_id_);
}

bool NodeGuarding::OnFrame(const CanFrame& frame) {
  if (!frame.remote() || frame.extended() || frame.error()) return false;
  if (!IsValidNodeId(node_id_) || frame.id != kErrorControlCobId + node_id_) return false;
  const NmtState state = state_ ? state_() : NmtState::kInitialising;
  if (state == NmtState::kInitialising) return true;

  // CiA 301 §7.2.8.3.2.1: reply with the toggle bit, which starts at 0 and alternates.
  const auto reply =
      static_cast<std::uint8_t>((toggle_ ? 0x80 : 0x00) | (static_cast<std::uint8_t>(state) & 0x7F));
  toggle_ = !toggle_;
  port_.Send(CanFrame::Data(kErrorControlCobId + node_id_, {reply}));

  const Duration life_time = LifeTime();
  if (life_time == Duration::zero()) return true;
  guarding_started_ = true;
  life_timer_.StartAfter(life_time);
  if (timed_out_) ClearTimeout();
  return true;
}

void NodeGuarding::Reset() {
  toggle_ = false;
  StopLifeGuarding();
}

void NodeGuarding::StopLifeGuarding() {
  guarding_started_ = false;
  life_timer_.Cancel();
  if (timed_out_) ClearTimeout();
}

void NodeGuarding::ClearTimeout() {
  timed_out_ = false;
  // The node-ID the error was raised with: reset communication may have changed it since.
  errors_.OnCommError({CommErrorKind::kLifeGuardTimeout, reported_node_id_}, false);
}

void NodeGuarding::OnConfigChanged() {
  if (!guarding_started_) return;
  const Duration life_time = LifeTime();
  if (life_time == Duration::zero()) {
    StopLifeGuarding();
    return;
  }
  // A new life time counts from now; an expired one stays expired until the next request.
  if (!timed_out_) life_timer_.StartAfter(life_time);
}

void NodeGuarding::OnLifeTimeExpired() {
  if (timed_out_) return;
  timed_out_ = true;
  reported_node_id_ = node_id_;
  errors_.OnCommError({CommErrorKind::kLifeGuardTimeout, reported_node_id_}, true);
}

void AddGuardingObjects(ObjectDictionary& od) {
  od.AddVar(kGuardTimeIndex, "Guard time", DataType::kUnsigned16, Access::kRw, EncodeLe<std::uint16_t>(0));
  od.AddVar(kLifeTimeFactorIndex, "Life time factor", DataType::kUnsigned8, Access::kRw, {0});
}

}  // namespace canfleet::canopen
