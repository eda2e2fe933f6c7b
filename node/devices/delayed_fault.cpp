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

void DelayedFault::Update(bool present, Duration delay) {
  switch (state_) {
    case State::kInactive:
      if (!present) return;
      if (delay <= Duration::zero()) {
        Activate();
      } else {
        state_ = State::kPending;
        timer_.StartAfter(delay);
      }
      return;
    case State::kPending:
      if (!present) {
        timer_.Cancel();
        state_ = State::kInactive;
      }
      return;
    case State::kActive:
      if (!present) {
        state_ = State::kInactive;
        stack_.emcy().Clear(entry_.code, entry_.info);
      }
      return;
  }
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
