#include "node/devices/device_port.hpp"

namespace canfleet::devices {

DevicePort::DevicePort(BusPort& port) : port_(port) {
  port_.OnReceive([this](const CanFrame& frame, BusTime time) {
    if (observer_) observer_(frame);
    Deliver(frame, time);
  });
  port_.OnStateChange([this](const ControllerEvent& event) { NotifyState(event); });
}

DevicePort::~DevicePort() {
  port_.OnReceive(nullptr);
  port_.OnStateChange(nullptr);
}

bool DevicePort::Send(const CanFrame& frame) {
  if (muted_) return false;
  return port_.Send(frame);
}

}  // namespace canfleet::devices
