#include "node/devices/encoder_dual_valve/valve_outputs.hpp"

#include <algorithm>
#include <cmath>

#include "node/devices/family/family_error_policy.hpp"

namespace canfleet::devices::encoder {

using blocks::SourceKind;

ValveOutputs::ValveOutputs(canopen::CanopenStack& stack, Scheduler& scheduler, EncoderIo& io) : io_(io) {
  auto& od = stack.od();
  for (int n = 0; n < kOutputs; ++n) {
    const std::uint8_t sub = SubOf(n);
    Refs& r = refs_[n];
    r.type = OdRef(od, kAoOutputType, sub);
    r.fv_min = OdRef(od, kAoScaling1Fv, sub);
    r.fv_max = OdRef(od, kAoScaling2Fv, sub);
    r.fv_digits = OdRef(od, kAoFvDigits, sub);
    r.ramp_up = OdRef(od, kAoRampUp, sub);
    r.ramp_down = OdRef(od, kAoRampDown, sub);
    r.override_fv = OdRef(od, kAoOverrideFv, sub);
    r.override_response = OdRef(od, kAoOverrideResponse, sub);
    r.fault_mode = OdRef(od, kAoFaultMode, sub);
    r.fault_fv = OdRef(od, kAoFaultFv, sub);
    r.do_fault_mode = OdRef(od, kDoFaultMode, sub);
    r.do_fault_state = OdRef(od, kDoFaultState, sub);
    r.delay_time = OdRef(od, kDoDelayTime, sub);
    r.delay_polarity = OdRef(od, kDoDelayPolarity, sub);
    r.control_source = OdRef(od, kAoControlSource, sub);
    r.control_number = OdRef(od, kAoControlNumber, sub);
    r.enable_source = OdRef(od, kAoEnableSource, sub);
    r.enable_number = OdRef(od, kAoEnableNumber, sub);
    r.override_source = OdRef(od, kAoOverrideSource, sub);
    r.override_number = OdRef(od, kAoOverrideNumber, sub);
    r.field_value = OdRef(od, kAoFieldValue, sub);
    r.feedback = OdRef(od, kAoFeedback, sub);
    r.error_enable = OdRef(od, kAoErrorEnable, sub);
    r.hysteresis = OdRef(od, kAoErrorHysteresis, sub);
    r.error_delay = OdRef(od, kAoErrorDelay, sub);
    r.frequency = OdRef(od, kAoFrequency, sub);
    const auto fault = [&](std::uint8_t description, std::uint8_t behaviour) {
      return std::make_unique<DelayedFault>(
          scheduler, stack, family::MakeFamilyEntry(kEmcyOutput, description, sub), behaviour);
    };
    Faults& f = faults_[n];
    f.open_ao = fault(kDescOpen, kBehaviourAnalogOutput);
    f.short_ao = fault(kDescShort, kBehaviourAnalogOutput);
    f.open_do = fault(kDescOpen, kBehaviourDigitalOutput);
    f.short_do = fault(kDescShort, kBehaviourDigitalOutput);
  }
  write_state_ = OdRef(od, kDoWriteState, 1);
  polarity_ = OdRef(od, kDoPolarity, 1);
}

DriveConfig ValveOutputs::Config(int n) const {
  const Refs& r = refs_[n];
  DriveConfig c;
  c.type = static_cast<OutputType>(r.type.Get());
  c.fv_min = static_cast<double>(r.fv_min.Get());
  c.fv_max = static_cast<double>(r.fv_max.Get());
  c.fv_digits = static_cast<std::uint8_t>(std::clamp<std::int64_t>(r.fv_digits.Get(), 0, 3));
  c.ramp_up_ms = r.ramp_up.Get();
  c.ramp_down_ms = r.ramp_down.Get();
  c.override_fv = static_cast<double>(r.override_fv.Get());
  c.override_when_off = r.override_response.Get() == 1;
  c.fault_response = static_cast<std::uint8_t>(r.fault_mode.Get());
  c.fault_fv = static_cast<double>(r.fault_fv.Get());
  c.do_fault_apply = r.do_fault_mode.Get() != 0;
  c.do_fault_state = r.do_fault_state.Get() != 0;
  c.delay_ms = r.delay_time.Get();
  c.delay_on_edge = r.delay_polarity.Get() == 1;
  return c;
}

DriveSource ValveOutputs::Source(const blocks::ControlSources& sources, const OdRef& source,
                                 const OdRef& number) const {
  DriveSource s;
  const blocks::SourceRef ref{static_cast<std::uint8_t>(source.Get()),
                              static_cast<std::uint8_t>(number.Get())};
  s.used = sources.KindOf(ref.source) != SourceKind::kNotUsed;
  s.signal = sources.Resolve(ref);
  return s;
}

// 4.3: "Configurable frequency ONLY if no current output types are used, otherwise default 25kHz".
double ValveOutputs::PwmFrequency(int n) const {
  for (const Refs& r : refs_) {
    if (IsCurrentControlled(static_cast<OutputType>(r.type.Get()))) return OutputDrive::kDriverFrequency_Hz;
  }
  return std::clamp(static_cast<double>(refs_[n].frequency.Get()) * 1000.0, 1.0,
                    OutputDrive::kDriverFrequency_Hz);
}

void ValveOutputs::Update(Ms elapsed, const OutputConditions& conditions,
                          const blocks::ControlSources& sources) {
  for (int n = 0; n < kOutputs; ++n) {
    Refs& r = refs_[n];
    const DriveConfig config = Config(n);
    DriveCommand command;
    const auto control_code = static_cast<std::uint8_t>(r.control_source.Get());
    command.direct = sources.KindOf(control_code) == SourceKind::kNotUsed;
    command.control = Source(sources, r.control_source, r.control_number);
    command.enable = Source(sources, r.enable_source, r.enable_number);
    command.override_input = Source(sources, r.override_source, r.override_number);
    command.direct_fv = static_cast<double>(r.field_value.Get());
    command.direct_on = write_state_.Bit(static_cast<unsigned>(n)) != polarity_.Bit(static_cast<unsigned>(n));
    const bool can_controlled = sources.KindOf(control_code) == SourceKind::kCanMessage;
    command.shutdown = conditions.all_off || conditions.nmt == canopen::NmtState::kStopped ||
                       (can_controlled && conditions.nmt != canopen::NmtState::kOperational);

    LoadModel load;
    load.supply_V = io_.supply->Number() / 1000.0;
    const IoSignal& state = *io_.load[n];
    load.load = state.Is(kLoadOpen)    ? LoadState::kOpen
                : state.Is(kLoadShort) ? LoadState::kShort
                                       : LoadState::kNominal;
    load.resistance_ohm = io_.resistance[n]->Number();
    load.pwm_frequency_Hz = PwmFrequency(n);

    OutputDrive& drive = drives_[n];
    drive.Step(elapsed, config, command, load);
    const DriveOutput& out = drive.Output();
    if (!command.direct) r.field_value.SetNumber(std::round(out.target_fv));
    r.feedback.SetNumber(std::round(out.current_mA));
    Publish(n);

    const bool detect = r.error_enable.Get() != 0;
    const bool open = detect && IsCurrentControlled(config.type) && out.driving && !out.tripped &&
                      out.desired_mA - out.current_mA > static_cast<double>(r.hysteresis.Get());
    const bool shorted = detect && out.tripped;
    const bool digital = IsDigital(config.type);
    const Duration delay = std::chrono::milliseconds(r.error_delay.Get());
    Faults& f = faults_[n];
    f.open_ao->Update(open && !digital, delay);
    f.short_ao->Update(shorted && !digital, delay);
    f.open_do->Update(open && digital, delay);
    f.short_do->Update(shorted && digital, delay);
  }
}

void ValveOutputs::Publish(int n) {
  const DriveOutput& out = drives_[n].Output();
  SimulatedIo& io = io_.io;
  io.Publish(*io_.current[n], out.current_mA);
  io.Publish(*io_.voltage[n], out.voltage_V * 1000.0);
  io.Publish(*io_.out_duty[n], out.duty_pct);
  io.Publish(*io_.out_frequency[n], out.frequency_Hz);
  io.Publish(*io_.on[n], out.on);
  io.Publish(*io_.hotshot[n], out.hotshot);
  io.Publish(*io_.tripped[n], out.tripped);
}

std::optional<ValveOutputs::Ms> ValveOutputs::NextChange() const {
  std::optional<Ms> next;
  for (const OutputDrive& d : drives_) {
    if (auto c = d.NextChange()) next = next ? std::min(*next, *c) : *c;
  }
  return next;
}

void ValveOutputs::Reset() {
  for (int n = 0; n < kOutputs; ++n) {
    drives_[n].Reset();
    Faults& f = faults_[n];
    f.open_ao->Reset();
    f.short_ao->Reset();
    f.open_do->Reset();
    f.short_do->Reset();
  }
}

blocks::Signal ValveOutputs::Target(int n) const {
  const Refs& r = refs_[n];
  blocks::Signal s;
  s.value = static_cast<double>(r.field_value.Get());
  s.min = static_cast<double>(r.fv_min.Get());
  s.max = static_cast<double>(r.fv_max.Get());
  s.decimal_digits = static_cast<std::uint8_t>(r.fv_digits.Get());
  return s;
}

blocks::Signal ValveOutputs::Feedback(int n) const {
  blocks::Signal s;
  s.value = static_cast<double>(refs_[n].feedback.Get());
  s.min = 0.0;
  s.max = TypeRange(OutputType::kCurrent);
  return s;
}

}  // namespace canfleet::devices::encoder
