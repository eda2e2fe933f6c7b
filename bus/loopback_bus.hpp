#pragma once
/// @file An in-process CAN bus for unit tests: every frame sent on one port reaches all others.

#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "bus/bus_port.hpp"

namespace canfleet {

class LoopbackBus;

/// One attachment to a LoopbackBus.
class LoopbackPort final : public BusPort {
 public:
  LoopbackPort(LoopbackBus& bus, std::string name) : bus_(bus), name_(std::move(name)) {}

  bool Send(const CanFrame& frame) override;
  ControllerState State() const override { return state_.state; }
  const std::string& Name() const { return name_; }

  /// Test control: puts this port's controller in a state and tells the port's user.
  void SetControllerState(const ControllerEvent& event);

 private:
  friend class LoopbackBus;
  LoopbackBus& bus_;
  std::string name_;
  ControllerEvent state_;
};

/// Delivers frames synchronously but never re-entrantly: a frame sent from inside a receive
/// handler is queued and delivered after the current one, so a request/response exchange between
/// two stacks runs to completion inside the first Send(), in bus order, without recursion.
/// There is no timing model and no arbitration: that lives in the broker.
class LoopbackBus {
 public:
  /// Attaches a new port. The reference stays valid for the bus's lifetime.
  LoopbackPort& Attach(std::string name);

  /// Every frame that went over the bus, in order (for assertions).
  const std::vector<CanFrame>& History() const { return history_; }
  void ClearHistory() { history_.clear(); }

 private:
  friend class LoopbackPort;
  void Transmit(const LoopbackPort& sender, const CanFrame& frame);

  struct Pending {
    const LoopbackPort* sender;
    CanFrame frame;
  };
  std::vector<std::unique_ptr<LoopbackPort>> ports_;
  std::deque<Pending> queue_;
  std::vector<CanFrame> history_;
  bool draining_ = false;
};

}  // namespace canfleet
