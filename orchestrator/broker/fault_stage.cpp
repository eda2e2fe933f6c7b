#include "orchestrator/broker/fault_stage.hpp"

#include <utility>

#include "orchestrator/broker/fault_rules.hpp"
#include "orchestrator/broker/virtual_bus.hpp"

namespace canfleet::broker {

const char* ToString(RuleAction action) {
  switch (action) {
    case RuleAction::kDrop:
      return "drop";
    case RuleAction::kDelay:
      return "delay";
    case RuleAction::kCorrupt:
      return "corrupt";
    case RuleAction::kDuplicate:
      return "duplicate";
  }
  return "?";
}

RuleId FaultStage::Add(FaultRule rule) {
  return rules_.Add(std::move(rule), scheduler_.Now().time_since_epoch());
}

bool FaultStage::Remove(RuleId id) {
  return rules_.Remove(id);
}

void FaultStage::Clear() {
  rules_.Clear();
}

std::vector<RuleStatus> FaultStage::List() const {
  return rules_.List(scheduler_.Now().time_since_epoch());
}

bool FaultStage::ForceBusOff(PortId port, bool hold) {
  return bus_.ForceBusOff(bus_.PortOnBus(port), hold);
}

bool FaultStage::HoldBusOff(PortId port, bool on) {
  return bus_.HoldBusOff(bus_.PortOnBus(port), on);
}

bool FaultStage::HoldErrorPassive(PortId port, bool on) {
  return bus_.HoldErrorPassive(bus_.PortOnBus(port), on);
}

bool FaultStage::StartBabbling(PortId port, const CanFrame& frame) {
  return bus_.StartBabbling(bus_.PortOnBus(port), frame);
}

bool FaultStage::StopBabbling(PortId port) {
  return bus_.StopBabbling(bus_.PortOnBus(port));
}

}  // namespace canfleet::broker
