#include "node/canopen/heartbeat/heartbeat_producer.hpp"

#include <chrono>
#include <utility>

#include "node/canopen/nmt/error_control.hpp"

namespace canfleet::canopen {

HeartbeatProducer::HeartbeatProducer(ObjectDictionary& od, BusPort& port, Scheduler& scheduler,
                                     std::function<NmtState()> state)
    : od_(od), port_(port), state_(std::move(state)), timer_(scheduler, [this] { OnTimer(); }) {
  if (SubObject* sub = od_.Find(kProducerHeartbeatTimeIndex, 0)) {
    // CiA 301 §7.2.8.3.2.2: a new producer time applies at once; restart the period from now.
    sub->AddListener([this](SubObject&, Origin) {
      if (running_) Arm();
    });
  }
}

void HeartbeatProducer::SetNodeId(std::uint8_t node_id) {
  node_id_ = node_id;
  // Its timer sends the heartbeat and nothing else: in virtual time, a node that does not listen
  // to it is not held back by it (Timer::Confine).
  timer_.Confine(IsValidNodeId(node_id_) ? (kErrorControlCobId + node_id_) | Timer::kHeartbeat
                                         : Timer::kUnconfined);
}

Duration HeartbeatProducer::Period() const {
  return std::chrono::milliseconds(od_.GetUnsigned(kProducerHeartbeatTimeIndex, 0) & 0xFFFF);
}

void HeartbeatProducer::Start() {
  running_ = true;
  Arm();
}

void HeartbeatProducer::Stop() {
  running_ = false;
  timer_.Cancel();
}

void HeartbeatProducer::Arm() {
  Duration period = Period();
  if (period == Duration::zero()) {
    timer_.Cancel();
    return;
  }
  timer_.StartAfter(period);
}

void HeartbeatProducer::OnTimer() {
  Duration period = Period();
  if (period == Duration::zero()) return;
  // Next deadline from the previous one, not from now: no drift however late the callback runs.
  timer_.StartAt(timer_.Deadline() + period);
  NmtState state = state_ ? state_() : NmtState::kInitialising;
  // During a reset the node is Initialising and is not on the network: its next frame is the
  // boot-up, sent by the NMT slave.
  if (state == NmtState::kInitialising || !IsValidNodeId(node_id_)) return;
  port_.Send(CanFrame::Data(kErrorControlCobId + node_id_, {static_cast<std::uint8_t>(state)}));
}

}  // namespace canfleet::canopen
