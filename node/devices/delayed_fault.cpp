#include "node/devices/delayed_fault.hpp"

namespace canfleet::devices {

using canopen::NmtState;

void ApplyErrorBehaviour(canopen::CanopenStack& stack, std::uint8_t sub) {
  if (sub == 0) return;
  const canopen::SubObject* behaviour = stack.od().Find(0x1029, sub);
  if (!behaviour) return;
  const auto reaction = canopen::DecodeUnsignedLe(behaviour->value);
  if (reaction == 0 && stack.State() == NmtState::kOperational) stack.SetState(NmtState::kPreOperational);
  if (reaction == 2 && stack.State() != NmtState::kStopped) stack.SetState(NmtState::kStopped);
}

DelayedFault::DelayedFault(Scheduler& scheduler, canopen::CanopenStack& stack, canopen::ErrorEntry entry,
                           std::uint8_t behaviour_sub)
    : stack_(stack),
      entry_(entry),
      behaviour_sub_(behaviour_sub),
      timer_(scheduler, [this] { Activate(); }) {}

bool DelayedFault::Update(bool present, Duration delay) {
  switch (state_) {
    case State::kInactive:
      if (!present) return false;
      if (delay <= Duration::zero()) {
        Activate();
      } else {
        state_ = State::kPending;
        timer_.StartAfter(delay);
      }
      return true;
    case State::kPending:
      if (present) return false;
      timer_.Cancel();
      state_ = State::kInactive;
      return true;
    case State::kActive:
      if (present) return false;
      state_ = State::kInactive;
      stack_.emcy().Clear(entry_.code, entry_.info);
      return true;
  }
  return false;
}

void DelayedFault::Reset() {
  timer_.Cancel();
  state_ = State::kInactive;
}

void DelayedFault::Activate() {
  state_ = State::kActive;
  stack_.emcy().Raise(entry_);
  ApplyErrorBehaviour(stack_, behaviour_sub_);
}

}  // namespace canfleet::devices
