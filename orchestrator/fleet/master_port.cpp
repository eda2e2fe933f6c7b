#include "orchestrator/fleet/master_port.hpp"

namespace canfleet::fleet {

MasterPort::MasterPort(broker::Broker& broker, std::string bus) : broker_(broker), bus_(std::move(bus)) {
  port_ = broker_.Attach(bus_, "canfleet-master", *this);
}

MasterPort::~MasterPort() {
  broker_.Detach(port_);
}

bool MasterPort::Send(const CanFrame& frame) {
  return broker_.Submit(port_, frame) == 1;
}

void MasterPort::Deliver(std::span<const broker::TimedFrame> frames) {
  for (const auto& timed : frames) {
    for (const auto& observer : observers_)
      observer(timed.frame, timed.time);
    BusPort::Deliver(timed.frame, timed.time);
  }
}

void MasterPort::ControllerChanged(const ControllerEvent& event) {
  state_ = event.state;
  NotifyState(event);
}

}  // namespace canfleet::fleet
