#include "node/devices/power_supply_24v_350w/output_control.hpp"

#include <chrono>

#include "node/devices/family/family_error_policy.hpp"
#include "node/devices/power_supply_24v_350w/ps_objects.hpp"

namespace canfleet::devices::ps {

std::string_view StateName(OutputState state) {
  switch (state) {
    case OutputState::kOff:
      return "off";
    case OutputState::kOn:
      return "on";
    case OutputState::kShutdownDelay:
      return "shutdown_delay";
    case OutputState::kFault:
      return "fault";
    case OutputState::kFaultLatched:
      return "fault_latched";
    case OutputState::kProtection:
      return "protection";
  }
  return "off";
}

OutputControl::OutputControl(canopen::CanopenStack& stack) : stack_(stack) {
  auto& od = stack.od();
  control_mode_ = OdRef(od, kGeneralCommands, 1);
  on_off_ = OdRef(od, kOutputCommands, 2);
  base_delay_ = OdRef(od, kBaseShutdownDelay, 0);
  ack_delay_ = OdRef(od, kAckShutdownDelay, 0);
  ack_ = OdRef(od, kShutdownAck, 0);
  deglitch_ = OdRef(od, kEnableDeglitch, 0);
  latch_enable_ = OdRef(od, kEnableDs453Fault, 0);
}

void OutputControl::Reset(bool pin_high) {
  pin_ = pin_high;
  low_since_.reset();
  last_can_value_ = static_cast<std::uint8_t>(on_off_.Get());
  last_change_on_ = pin_high;
  command_ = false;
  enabled_ = false;
  latched_ = false;
  quit_requested_ = false;
  failure_ = false;
  input_ok_ = true;
  shutdown_at_.reset();
}

void OutputControl::OnCanCommand(std::uint8_t value) {
  const bool change = value != last_can_value_;
  last_can_value_ = value;
  if (change && (value == kCommandOn || value == kCommandOff)) last_change_on_ = value == kCommandOn;
}

void OutputControl::OnShutdownAck(std::uint8_t value, TimePoint now) {
  // §1.2.1.1: "If this message is received with value 0x01, the countdown timer will be updated to
  // the value set by object 2303h ... If the current countdown is already lower ... no change."
  if (value != 1 || !shutdown_at_) return;
  const TimePoint acknowledged = now + std::chrono::milliseconds(ack_delay_.Get());
  if (acknowledged < *shutdown_at_) shutdown_at_ = acknowledged;
}

void OutputControl::EndShutdown() {
  if (!shutdown_at_) return;
  shutdown_at_.reset();
  const auto entry = family::MakeFamilyEntry(kEmcyShutdown, kDescriptionShutdown, 0);
  stack_.emcy().Clear(entry.code, entry.info);
}

bool OutputControl::Update(const Inputs& in, TimePoint now) {
  const bool command_before = command_;
  const bool enabled_before = enabled_;
  const bool latched_before = latched_;
  const bool shutting_down_before = ShuttingDown();
  const OutputState state_before = State();

  // §1.2.1.2: a LOW is read only once it has lasted 2310h ms; a HIGH at once.
  if (in.pin_high) {
    low_since_.reset();
    if (!pin_) {
      pin_ = true;
      last_change_on_ = true;
    }
  } else if (pin_) {
    if (!low_since_) {
      low_since_ = now;
      low_delay_ = std::chrono::milliseconds(deglitch_.Get());
    }
    if (now - *low_since_ >= low_delay_) {
      low_since_.reset();
      pin_ = false;
      last_change_on_ = false;
    }
  }

  // Table 1 and Table 2.
  switch (static_cast<std::uint8_t>(control_mode_.Get())) {
    case kControlLocal:
      command_ = pin_;
      break;
    case kControlRemote: {
      const auto value = static_cast<std::uint8_t>(on_off_.Get());
      if (value == kCommandOn) command_ = true;
      if (value == kCommandOff) command_ = false;
      break;
    }
    default:
      command_ = last_change_on_;
      break;
  }

  // §1.2.3 and 2320h: the fault state holds until Quit Failure, which only acts when the failure
  // is gone ("If the device has entered fault state, the device will transition to the regular
  // operation state").
  const bool latching = latch_enable_.Get() == 1;
  if (!latching) latched_ = false;
  if (in.failure && latching) latched_ = true;
  if (quit_requested_) {
    if (!in.failure) latched_ = false;
    quit_requested_ = false;
  }

  // §1.2.1.1 Fig. 1.
  if (in.failure || latched_) {
    enabled_ = false;
    EndShutdown();
  } else if (command_) {
    enabled_ = true;
    EndShutdown();
  } else if (shutdown_at_) {
    if (now >= *shutdown_at_) {
      enabled_ = false;
      EndShutdown();
    }
  } else if (enabled_ && in.input_ok) {
    const auto delay = base_delay_.Get();
    if (delay <= 0) {
      enabled_ = false;
    } else {
      shutdown_at_ = now + std::chrono::milliseconds(delay);
      ack_.Set(0);
      stack_.emcy().Raise(family::MakeFamilyEntry(kEmcyShutdown, kDescriptionShutdown, 0));
    }
  } else {
    enabled_ = false;
  }
  failure_ = in.failure;
  input_ok_ = in.input_ok;
  return command_ != command_before || enabled_ != enabled_before || latched_ != latched_before ||
         ShuttingDown() != shutting_down_before || State() != state_before;
}

OutputState OutputControl::State() const {
  if (latched_) return OutputState::kFaultLatched;
  if (failure_) return OutputState::kFault;
  if (shutdown_at_) return OutputState::kShutdownDelay;
  if (enabled_ && !input_ok_) return OutputState::kProtection;
  return enabled_ ? OutputState::kOn : OutputState::kOff;
}

}  // namespace canfleet::devices::ps
