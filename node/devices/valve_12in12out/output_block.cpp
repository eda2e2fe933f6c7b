#include "node/devices/valve_12in12out/output_block.hpp"

#include <algorithm>
#include <cmath>

#include "node/devices/blocks/signal.hpp"
#include "node/devices/family/family_error_policy.hpp"

namespace canfleet::devices::valve {

namespace {

using blocks::Signal;
using namespace std::chrono_literals;

constexpr std::chrono::milliseconds kStep{1};

blocks::SourceRef Ref(const OdRef& source, const OdRef& number) {
  return {static_cast<std::uint8_t>(source.Get()), static_cast<std::uint8_t>(number.Get())};
}

std::chrono::milliseconds Ms(Duration d) {
  return std::chrono::duration_cast<std::chrono::milliseconds>(d);
}

/// What the three inputs of an output say this run (§1.4 a-c, §1.5).
struct Decision {
  Signal control;
  bool fault = false;
  bool override_active = false;
  bool enabled = true;
  std::int64_t enable_response = 0;
};

}  // namespace

OutputBlock::OutputBlock(canopen::CanopenStack& stack, Scheduler& scheduler, ValveIo& io,
                         const ValveSources& sources)
    : io_(io), sources_(sources) {
  auto& od = stack.od();
  dither_frequency_ = OdRef(od, kAoDitherFrequency, 1);
  dither_amplitude_ = OdRef(od, kAoDitherAmplitude, 1);
  for (int ch = 0; ch < kOutputs; ++ch) {
    const std::uint8_t sub = SubOf(ch);
    Refs& r = refs_[ch];
    r.type = OdRef(od, kAoType, sub);
    r.control_source = OdRef(od, kAoControlSource, sub);
    r.control_number = OdRef(od, kAoControlNumber, sub);
    r.response = OdRef(od, kAoControlResponse, sub);
    r.enable_source = OdRef(od, kAoEnableSource, sub);
    r.enable_number = OdRef(od, kAoEnableNumber, sub);
    r.enable_response = OdRef(od, kAoEnableResponse, sub);
    r.override_source = OdRef(od, kAoOverrideSource, sub);
    r.override_number = OdRef(od, kAoOverrideNumber, sub);
    r.override_response = OdRef(od, kAoOverrideResponse, sub);
    r.override_fv = OdRef(od, kAoOverrideFv, sub);
    r.s1_pv = OdRef(od, kAoScaling1Pv, sub);
    r.s1_fv = OdRef(od, kAoScaling1Fv, sub);
    r.s2_pv = OdRef(od, kAoScaling2Pv, sub);
    r.s2_fv = OdRef(od, kAoScaling2Fv, sub);
    r.fv_digits = OdRef(od, kAoFvDigits, sub);
    r.fault_mode = OdRef(od, kAoFaultMode, sub);
    r.fault_fv = OdRef(od, kAoFaultFv, sub);
    r.do_fault_mode = OdRef(od, kDoFaultMode, sub);
    r.do_fault_state = OdRef(od, kDoFaultState, sub);
    r.ramp_up = OdRef(od, kAoRampUp, sub);
    r.ramp_down = OdRef(od, kAoRampDown, sub);
    r.error_enable = OdRef(od, kAoErrorEnable, sub);
    r.error_tolerance = OdRef(od, kAoErrorTolerance, sub);
    r.error_delay = OdRef(od, kAoErrorDelay, sub);
    r.samples = OdRef(od, kAoFeedbackSamples, sub);
    r.commanded = OdRef(od, kAoFieldValue, sub);
    r.feedback = OdRef(od, kAoFeedback, sub);
    r.polarity = OdRef(od, kDoPolarity, sub);
    r.hotshot_current = OdRef(od, kDoHotshotCurrent, sub);
    r.hold_current = OdRef(od, kDoHoldCurrent, sub);
    r.hotshot_time = OdRef(od, kDoHotshotTime, sub);
    r.blink_rate = OdRef(od, kDoBlinkRate, sub);
    r.delay_time = OdRef(od, kDoDelayTime, sub);
    r.delay_polarity = OdRef(od, kDoDelayPolarity, sub);
    if (ch < kDiagnosedChannels) {
      const auto entry = family::MakeFamilyEntry(kEmcyOutputOverload, kDescSensorBreak, sub);
      channels_[ch].analog_fault =
          std::make_unique<DelayedFault>(scheduler, stack, entry, kBehaviourAnalogOutput);
      channels_[ch].digital_fault =
          std::make_unique<DelayedFault>(scheduler, stack, entry, kBehaviourDigitalOutput);
    }
  }
}

void OutputBlock::StartOver(Channel& c) {
  c.present = 0;
  c.ramping = false;
  c.drive = false;
  c.on_control = false;
  c.logic_prev = false;
  c.control_drive = false;
  c.delay_deadline.reset();
  c.latched = false;
  c.blink_start.reset();
  c.feedback.Reset();
  c.has_sample = false;
}

void OutputBlock::Reset() {
  for (Channel& c : channels_) {
    StartOver(c);
    c.type = -1;
    if (c.analog_fault) c.analog_fault->Reset();
    if (c.digital_fault) c.digital_fault->Reset();
  }
}

OutputScaling OutputBlock::Scaling(int ch) const {
  const Refs& r = refs_[ch];
  return {static_cast<double>(r.s1_pv.Get()), static_cast<double>(r.s1_fv.Get()),
          static_cast<double>(r.s2_pv.Get()), static_cast<double>(r.s2_fv.Get())};
}

namespace {

Decision Decide(const ValveSources& sources, const OdRef& control_source, const OdRef& control_number,
                const OdRef& enable_source, const OdRef& enable_number, const OdRef& enable_response,
                const OdRef& override_source, const OdRef& override_number, const OdRef& override_response) {
  Decision d;
  d.control = sources.Resolve(Ref(control_source, control_number));
  const Signal enable = sources.Resolve(Ref(enable_source, enable_number));
  const Signal override_in = sources.Resolve(Ref(override_source, override_number));
  // a) "No fault is detected for any of the control signals" (§1.4).
  d.fault = (d.control.available && d.control.error) || (enable.available && enable.error) ||
            (override_in.available && override_in.error);
  // b) Table 20: 0 override when ON, 1 override when OFF.
  if (override_in.available) d.override_active = IsOn(override_in) == (override_response.Get() == 0);
  // c) Table 19: 0-2 enable when ON, 3-5 enable when OFF.
  d.enable_response = enable_response.Get();
  if (enable.available) d.enabled = IsOn(enable) == (d.enable_response < 3);
  return d;
}

}  // namespace

void OutputBlock::RunAnalog(int ch, std::chrono::milliseconds elapsed, const OutputConditions& conditions) {
  Refs& r = refs_[ch];
  Channel& c = channels_[ch];
  const Decision d = Decide(sources_, r.control_source, r.control_number, r.enable_source, r.enable_number,
                            r.enable_response, r.override_source, r.override_number, r.override_response);
  const OutputScaling s = Scaling(ch);
  const auto ramp_to = [&](double target) {
    // The first step of a ramp is one millisecond: the time before it the output stood still.
    const auto step = c.ramping ? elapsed : kStep;
    c.present = RampStep(c.present, target, s, r.ramp_up.Get(), r.ramp_down.Get(), step);
    c.ramping = c.present != target;
  };
  const auto set = [&c](double value) {
    c.present = value;
    c.ramping = false;
  };
  if (conditions.stopped || conditions.supply_fault) {
    set(0);
  } else if (d.fault) {
    if (r.fault_mode.Get() == 1)
      set(static_cast<double>(r.fault_fv.Get()));
    else
      c.ramping = false;  // 0: maintain the last FV
  } else if (d.override_active) {
    set(static_cast<double>(r.override_fv.Get()));
  } else if (!d.enabled) {
    switch (d.enable_response % 3) {
      case 0:  // shut off
        set(0);
        break;
      case 1:  // ramp off
        ramp_to(0);
        break;
      default:  // keep the last value
        c.ramping = false;
        break;
    }
  } else {
    const double target = d.control.available
                              ? FieldValueOf(d.control.value, s, static_cast<std::uint8_t>(r.response.Get()))
                              : 0.0;
    ramp_to(target);
  }
  r.commanded.SetNumber(c.present);
}

// 2210h for the control path of a digital output (Table 12).
bool OutputBlock::ControlDrive(int ch, TimePoint now, bool logic) {
  Refs& r = refs_[ch];
  Channel& c = channels_[ch];
  if (!c.on_control) {  // (re-)entering the control path: no edge to react to
    c.logic_prev = logic;
    c.control_drive = logic;
    c.delay_deadline.reset();
    c.blink_start.reset();
  }
  auto polarity = static_cast<DoPolarity>(r.polarity.Get());
  // §1.4: the hotshot uses the output timer, so blinking "does not apply"; it acts as normal on/off.
  if (polarity == DoPolarity::kBlink && r.type.Get() == static_cast<std::int64_t>(OutputType::kHotshot))
    polarity = DoPolarity::kNormal;
  bool drive = false;
  switch (polarity) {
    case DoPolarity::kNormal: {
      // 2224h/2225h: the edge to the 2225h state waits 2224h ms; the other edge acts at once.
      const auto delay = std::chrono::milliseconds(r.delay_time.Get());
      const bool delayed_state = r.delay_polarity.Get() != 0;
      if (logic != c.logic_prev) {
        if (delay.count() > 0 && logic == delayed_state) {
          c.delay_deadline = now + delay;
          c.delay_target = logic;
        } else {
          c.delay_deadline.reset();
          c.control_drive = logic;
        }
      }
      if (c.delay_deadline && now >= *c.delay_deadline) {
        c.control_drive = c.delay_target;
        c.delay_deadline.reset();
      }
      drive = c.control_drive;
      break;
    }
    case DoPolarity::kInverse:
      drive = !logic;
      break;
    case DoPolarity::kLatched:
      if (logic && !c.logic_prev) c.latched = !c.latched;  // OFF -> ON toggles
      drive = c.latched;
      break;
    case DoPolarity::kBlink: {
      if (!logic) {
        c.blink_start.reset();
        break;
      }
      if (!c.blink_start) c.blink_start = now;
      const auto rate = r.blink_rate.Get();
      // ON for 2223h ms, OFF for 2223h ms, from the moment the logic turned ON; 0 = steady ON.
      drive = rate <= 0 || (Ms(now - *c.blink_start).count() / rate) % 2 == 0;
      break;
    }
  }
  c.logic_prev = logic;
  return drive;
}

void OutputBlock::RunDigital(int ch, TimePoint now, const OutputConditions& conditions) {
  Refs& r = refs_[ch];
  Channel& c = channels_[ch];
  const Decision d = Decide(sources_, r.control_source, r.control_number, r.enable_source, r.enable_number,
                            r.enable_response, r.override_source, r.override_number, r.override_response);
  bool drive = c.drive;
  bool commanded = drive;
  bool on_control = false;
  if (conditions.stopped || conditions.supply_fault) {
    drive = false;
  } else if (d.fault) {
    if (r.do_fault_mode.Get() != 0) drive = r.do_fault_state.Get() != 0;  // else maintain the last state
  } else if (d.override_active) {
    drive = r.override_fv.Get() != 0;
  } else if (!d.enabled) {
    if (d.enable_response % 3 != 2) drive = false;  // shut off / ramp off; 2, 5: keep the last state
  } else {
    const bool logic = d.control.available && LogicStateOf(d.control.value, Scaling(ch));
    drive = ControlDrive(ch, now, logic);
    commanded = logic;
    on_control = true;
  }
  if (!on_control) commanded = drive;
  c.on_control = on_control;
  if (drive && !c.drive) c.on_since = now;  // hotshot time starts at the ON edge
  c.drive = drive;
  r.commanded.Set(commanded ? 1 : 0);
}

void OutputBlock::Publish(int ch, TimePoint now) {
  Refs& r = refs_[ch];
  Channel& c = channels_[ch];
  const auto type = static_cast<OutputType>(c.type);
  const IoSignal& load = *io_.load[ch];
  const bool nominal = load.Is(kLoadNominal);
  const bool shorted = load.Is(kLoadShort);
  const double unit =
      blocks::PowerOfTen(static_cast<std::uint8_t>(std::clamp<std::int64_t>(r.fv_digits.Get(), 0, 4)));
  const double supply_mV = io_.supply->Number();
  double current_mA = 0;
  double voltage_mV = 0;
  double duty = 0;
  bool on = false;
  double sample = 0;
  bool dithering = false;
  switch (type) {
    case OutputType::kCurrent: {
      const double mA = std::max(0.0, c.present / unit);
      on = mA > 0 && !shorted;
      current_mA = nominal ? mA : 0.0;  // closed loop: the load takes the commanded current
      sample = current_mA * unit;
      dithering = current_mA > 0 && dither_amplitude_.Get() > 0;
      break;
    }
    case OutputType::kVoltage: {
      const double mV = std::clamp(c.present / unit, 0.0, supply_mV);
      on = mV > 0 && !shorted;
      voltage_mV = on ? mV : 0.0;
      duty = supply_mV > 0 ? mV / supply_mV * 100.0 : 0.0;
      sample = c.present;
      break;
    }
    case OutputType::kPwm: {
      duty = std::clamp(c.present / unit, 0.0, 100.0);
      on = duty > 0 && !shorted;
      voltage_mV = on ? duty / 100.0 * supply_mV : 0.0;
      sample = c.present;
      break;
    }
    case OutputType::kDigital:
      on = c.drive && !shorted;
      current_mA = c.drive && nominal ? io_.load_current[ch]->Number() : 0.0;
      voltage_mV = on ? supply_mV : 0.0;
      duty = on ? 100.0 : 0.0;
      sample = c.drive ? 1 : 0;
      break;
    case OutputType::kHotshot: {
      on = c.drive && !shorted;
      const bool hot = Ms(now - c.on_since) < std::chrono::milliseconds(r.hotshot_time.Get());
      const double mA = static_cast<double>(hot ? r.hotshot_current.Get() : r.hold_current.Get()) / unit;
      current_mA = c.drive && nominal ? mA : 0.0;
      sample = c.drive ? 1 : 0;
      break;
    }
    case OutputType::kDisabled:
      break;
  }
  SimulatedIo& sim = io_.io;
  sim.Publish(*io_.on[ch], on);
  sim.Publish(*io_.current_out[ch], current_mA);
  if (io_.voltage_out[ch]) {
    sim.Publish(*io_.voltage_out[ch], voltage_mV);
    sim.Publish(*io_.duty_out[ch], duty);
    sim.Publish(*io_.dither_amplitude[ch], dithering ? static_cast<double>(dither_amplitude_.Get()) : 0.0);
    sim.Publish(*io_.dither_frequency[ch], dithering ? static_cast<double>(dither_frequency_.Get()) : 0.0);
  }
  c.sample = sample;
}

bool OutputBlock::Run(TimePoint now, std::chrono::milliseconds elapsed, const OutputConditions& conditions) {
  bool changed = false;
  for (int ch = 0; ch < kOutputs; ++ch) {
    Refs& r = refs_[ch];
    Channel& c = channels_[ch];
    const std::int64_t commanded_before = r.commanded.Get();
    const std::int64_t feedback_before = r.feedback.Get();
    const std::int64_t type = r.type.Get();
    if (type != c.type) {
      StartOver(c);
      c.type = type;
    }
    const double previous_sample = c.sample;
    const bool had_sample = c.has_sample;
    if (IsDigitalType(type)) {
      RunDigital(ch, now, conditions);
    } else if (type == static_cast<std::int64_t>(OutputType::kDisabled)) {
      c.present = 0;
      c.ramping = false;
      r.commanded.Set(0);
    } else {
      RunAnalog(ch, elapsed, conditions);
    }
    Publish(ch, now);

    // 2370h: the time before this run carried the previous sample, this millisecond the new one.
    const auto samples = r.samples.Get();
    if (had_sample && elapsed > kStep) c.feedback.Add(previous_sample, (elapsed - kStep).count(), samples);
    c.feedback.Add(c.sample, kStep.count(), samples);
    c.has_sample = true;
    r.feedback.SetNumber(c.feedback.Value());

    if (c.analog_fault) {
      const bool detect = r.error_enable.Get() != 0;
      const IoSignal& load = *io_.load[ch];
      bool flag = false;
      bool digital = IsDigitalType(type);
      if (digital) {
        flag = c.drive && !load.Is(kLoadNominal);
      } else if (type == static_cast<std::int64_t>(OutputType::kCurrent)) {
        flag = std::abs(static_cast<double>(r.commanded.Get() - r.feedback.Get())) >
                   static_cast<double>(r.error_tolerance.Get()) ||
               (c.present > 0 && load.Is(kLoadShort));
      } else if (type != static_cast<std::int64_t>(OutputType::kDisabled)) {
        flag = c.present > 0 && load.Is(kLoadShort);
      }
      const Duration delay = std::chrono::milliseconds(r.error_delay.Get());
      c.analog_fault->Update(detect && flag && !digital, delay);
      c.digital_fault->Update(detect && flag && digital, delay);
    }
    changed |= r.commanded.Get() != commanded_before || r.feedback.Get() != feedback_before;
  }
  return changed;
}

std::optional<std::chrono::milliseconds> OutputBlock::NextWake(TimePoint now) const {
  std::optional<std::chrono::milliseconds> wake;
  const auto earliest = [&wake](std::chrono::milliseconds t) {
    t = std::max(t, kStep);
    wake = wake ? std::min(*wake, t) : t;
  };
  for (int ch = 0; ch < kOutputs; ++ch) {
    const Refs& r = refs_[ch];
    const Channel& c = channels_[ch];
    if (c.ramping) earliest(kStep);
    if (c.delay_deadline) earliest(Ms(*c.delay_deadline - now));
    if (c.blink_start && c.on_control) {
      const auto rate = r.blink_rate.Get();
      if (rate > 0) {
        const auto since = Ms(now - *c.blink_start).count();
        earliest(std::chrono::milliseconds(rate - since % rate));
      }
    }
    if (c.drive && c.type == static_cast<std::int64_t>(OutputType::kHotshot)) {
      const auto end = c.on_since + std::chrono::milliseconds(r.hotshot_time.Get());
      if (end > now) earliest(Ms(end - now) + (Ms(end - now) < end - now ? kStep : 0ms));
    }
    if (c.has_sample) {
      if (const auto until = c.feedback.UntilChange(c.sample, r.samples.Get()); until > 0)
        earliest(std::chrono::milliseconds(until));
    }
  }
  return wake;
}

}  // namespace canfleet::devices::valve
