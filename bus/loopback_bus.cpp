#include "bus/loopback_bus.hpp"

namespace canfleet {

bool LoopbackPort::Send(const CanFrame& frame) {
  if (!frame.valid() || state_.state == ControllerState::kBusOff) return false;
  bus_.Transmit(*this, frame);
  return true;
}

void LoopbackPort::SetControllerState(const ControllerEvent& event) {
  state_ = event;
  NotifyState(event);
}

LoopbackPort& LoopbackBus::Attach(std::string name) {
  ports_.push_back(std::make_unique<LoopbackPort>(*this, std::move(name)));
  return *ports_.back();
}

void LoopbackBus::Transmit(const LoopbackPort& sender, const CanFrame& frame) {
  queue_.push_back({&sender, frame});
  if (draining_) return;
  draining_ = true;
  while (!queue_.empty()) {
    Pending p = queue_.front();
    queue_.pop_front();
    history_.push_back(p.frame);
    // Index loop: a handler may attach ports (the vector may grow) while we deliver.
    for (std::size_t i = 0; i < ports_.size(); ++i) {
      if (ports_[i].get() != p.sender) ports_[i]->Deliver(p.frame, BusTime{0});
    }
  }
  draining_ = false;
}

}  // namespace canfleet
