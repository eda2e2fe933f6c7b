#pragma once
/// @file The orchestrator's own attachment to one bus: a CANopen master's port (NMT master, SDO
/// client) that also watches every frame for the node tracker. It is an ordinary node-role port on
/// the broker, as the master on a real network is an ordinary CAN controller: it acknowledges
/// frames, so a fleet's nodes are never alone on their bus.

#include <functional>
#include <span>
#include <string>
#include <vector>

#include "bus/bus_port.hpp"
#include "orchestrator/broker/broker.hpp"

namespace canfleet::fleet {

class MasterPort final : public BusPort, public broker::PortSink {
 public:
  using FrameObserver = std::function<void(const CanFrame&, BusTime)>;

  /// Attaches to `bus` as "canfleet-master". Detaches on destruction.
  MasterPort(broker::Broker& broker, std::string bus);
  ~MasterPort() override;
  MasterPort(const MasterPort&) = delete;
  MasterPort& operator=(const MasterPort&) = delete;

  const std::string& bus() const { return bus_; }

  /// Every frame other ports send, before BusPort's own receive handler (the SDO client) sees it.
  void AddObserver(FrameObserver observer) { observers_.push_back(std::move(observer)); }

  // BusPort
  bool Send(const CanFrame& frame) override;
  ControllerState State() const override { return state_; }

  // broker::PortSink
  void Deliver(std::span<const broker::TimedFrame> frames) override;
  void ControllerChanged(const ControllerEvent& event) override;

 private:
  broker::Broker& broker_;
  std::string bus_;
  broker::PortId port_ = 0;
  ControllerState state_ = ControllerState::kErrorActive;
  std::vector<FrameObserver> observers_;
};

}  // namespace canfleet::fleet
