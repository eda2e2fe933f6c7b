#include "bus/physics/fault_confinement.hpp"

#include <algorithm>

namespace canfleet {

std::optional<ControllerEvent> FaultConfinement::Update() {
  ControllerState next = state_;
  if (state_ == ControllerState::kBusOff) return std::nullopt;  // only Recover() leaves bus-off
  if (tec_ > 255)
    next = ControllerState::kBusOff;
  else if (tec_ >= 128 || rec_ >= 128)
    next = ControllerState::kErrorPassive;
  else
    next = ControllerState::kErrorActive;
  if (next == state_) return std::nullopt;
  state_ = next;
  return Snapshot();
}

std::optional<ControllerEvent> FaultConfinement::OnTransmitSuccess() {
  if (state_ == ControllerState::kBusOff) return std::nullopt;
  const std::uint16_t floor = hold_passive_ ? kErrorPassiveTec : 0;
  if (tec_ > floor) --tec_;
  return Update();
}

std::optional<ControllerEvent> FaultConfinement::OnTransmitError(TransmitError error) {
  if (state_ == ControllerState::kBusOff) return std::nullopt;
  if (error == TransmitError::kAck && state_ == ControllerState::kErrorPassive) return std::nullopt;
  tec_ = static_cast<std::uint16_t>(tec_ + 8);
  return Update();
}

std::optional<ControllerEvent> FaultConfinement::CountReceiveSuccess() {
  if (state_ == ControllerState::kBusOff) return std::nullopt;
  if (rec_ > 127)
    rec_ = 127;  // "a value between 119 and 127": we choose 127
  else if (rec_ > 0)
    --rec_;
  return Update();
}

std::optional<ControllerEvent> FaultConfinement::OnReceiveError() {
  if (state_ == ControllerState::kBusOff) return std::nullopt;
  if (rec_ < 255) ++rec_;
  return Update();
}

std::optional<ControllerEvent> FaultConfinement::Recover() {
  if (state_ != ControllerState::kBusOff) return std::nullopt;
  tec_ = hold_passive_ ? kErrorPassiveTec : 0;
  rec_ = 0;
  state_ = hold_passive_ ? ControllerState::kErrorPassive : ControllerState::kErrorActive;
  return Snapshot();
}

std::optional<ControllerEvent> FaultConfinement::ForceBusOff() {
  if (state_ == ControllerState::kBusOff) return std::nullopt;
  tec_ = 256;
  state_ = ControllerState::kBusOff;
  return Snapshot();
}

std::optional<ControllerEvent> FaultConfinement::HoldErrorPassive(bool on) {
  if (on == hold_passive_) return std::nullopt;
  hold_passive_ = on;
  if (state_ == ControllerState::kBusOff) return std::nullopt;  // Recover() applies the hold
  if (on)
    tec_ = std::max(tec_, kErrorPassiveTec);
  else
    tec_ = std::min(tec_, kReleasedTec);
  return Update();
}

}  // namespace canfleet
