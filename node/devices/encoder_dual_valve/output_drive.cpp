#include "node/devices/encoder_dual_valve/output_drive.hpp"

#include <algorithm>
#include <cmath>

namespace canfleet::devices::encoder {
namespace {

using Ms = OutputDrive::Ms;
constexpr Ms kTick{1};

Ms MinOpt(std::optional<Ms> a, Ms b) {
  return a ? std::min(*a, b) : b;
}

}  // namespace

double TypeRange(OutputType type) {
  switch (type) {
    case OutputType::kVoltage:
      return 60.0;
    case OutputType::kCurrent:
      return 2500.0;
    case OutputType::kPwm:
      return 100.0;
    case OutputType::kDigital:
    case OutputType::kHotshot:
      return 1.0;
    case OutputType::kDisabled:
      break;
  }
  return 0.0;
}

bool IsProportional(OutputType type) {
  return type == OutputType::kVoltage || type == OutputType::kCurrent || type == OutputType::kPwm;
}

bool IsDigital(OutputType type) {
  return type == OutputType::kDigital || type == OutputType::kHotshot;
}

bool IsCurrentControlled(OutputType type) {
  return type == OutputType::kCurrent || type == OutputType::kHotshot;
}

void OutputDrive::Reset() {
  *this = OutputDrive{};
}

void OutputDrive::Step(Ms elapsed, const DriveConfig& config, const DriveCommand& command,
                       const LoadModel& load) {
  const OutputType type = config.type;
  const double scale = blocks::PowerOfTen(config.fv_digits);
  const double type_hi = TypeRange(type) * scale;
  const double lo = std::clamp(std::min(config.fv_min, config.fv_max), 0.0, type_hi);
  const double hi = std::clamp(std::max(config.fv_min, config.fv_max), lo, type_hi);
  const auto clamp = [&](double fv) { return std::clamp(fv, lo, hi); };

  Kind kind = Kind::kFollow;
  double value = 0.0;
  bool on = false;
  if (type == OutputType::kDisabled || command.shutdown) {
    kind = Kind::kOff;
  } else if (command.control.Faulted() || command.enable.Faulted() || command.override_input.Faulted()) {
    if (IsDigital(type)) {
      kind = config.do_fault_apply ? Kind::kSet : Kind::kHold;
      on = config.do_fault_state;
    } else if (config.fault_response == 1) {
      kind = Kind::kSet;
      value = clamp(config.fault_fv);
    } else {
      kind = config.fault_response == 2 ? Kind::kHold : Kind::kOff;
    }
  } else if (command.override_input.used && command.override_input.signal.available &&
             command.override_input.On() != config.override_when_off) {
    value = clamp(config.override_fv);
    on = config.override_fv != 0.0;
  } else if (command.enable.used && !command.enable.On()) {
    kind = Kind::kOff;
  } else if (command.direct) {
    value = clamp(command.direct_fv);
    on = command.direct_on;
  } else if (command.control.used && command.control.signal.available) {
    const double fraction = command.control.signal.ToPercent() / 100.0;
    value = clamp(config.fv_min + fraction * (config.fv_max - config.fv_min));
    on = command.control.On();
  } else {
    kind = Kind::kOff;  // a control source that delivers nothing (e.g. a lookup table not set up)
  }

  if (IsDigital(type)) {
    StepDigital(elapsed, config, kind, on);
  } else {
    StepProportional(elapsed, config, kind, value);
    requested_on_ = commanded_on_ = false;
    delay_running_ = false;
  }
  Drive(elapsed, config, load);
}

void OutputDrive::StepProportional(Ms elapsed, const DriveConfig& config, Kind kind, double value) {
  switch (kind) {
    case Kind::kOff:
      present_ = target_ = 0.0;
      ramping_ = false;
      return;
    case Kind::kSet:
      present_ = target_ = value;
      ramping_ = false;
      return;
    case Kind::kHold:
      target_ = present_;
      ramping_ = false;
      return;
    case Kind::kFollow:
      break;
  }
  // A ramp that was not running starts now: the time before belongs to the previous target.
  const Ms e = ramping_ ? elapsed : std::min(elapsed, kTick);
  target_ = value;
  const bool up = target_ > present_;
  const std::int64_t ramp_ms = up ? config.ramp_up_ms : config.ramp_down_ms;
  double range = std::abs(config.fv_max - config.fv_min);
  if (range == 0.0) range = TypeRange(config.type) * blocks::PowerOfTen(config.fv_digits);
  if (ramp_ms <= 0 || range <= 0.0) {
    present_ = target_;
  } else {
    const double step = range / static_cast<double>(ramp_ms) * static_cast<double>(e.count());
    present_ = up ? std::min(target_, present_ + step) : std::max(target_, present_ - step);
  }
  ramping_ = present_ != target_;
}

void OutputDrive::StepDigital(Ms elapsed, const DriveConfig& config, Kind kind, bool on) {
  ramping_ = false;
  switch (kind) {
    case Kind::kOff:
      requested_on_ = commanded_on_ = false;
      delay_running_ = false;
      break;
    case Kind::kSet:
      requested_on_ = commanded_on_ = on;
      delay_running_ = false;
      break;
    case Kind::kHold:
      requested_on_ = commanded_on_;
      delay_running_ = false;
      break;
    case Kind::kFollow: {
      requested_on_ = on;
      if (requested_on_ == commanded_on_) {
        delay_running_ = false;
        break;
      }
      const bool delayed =
          config.delay_ms > 0 && (requested_on_ ? config.delay_on_edge : !config.delay_on_edge);
      if (!delayed) {
        commanded_on_ = requested_on_;
        delay_running_ = false;
      } else if (!delay_running_) {
        delay_running_ = true;  // counts from this evaluation on
        delay_left_ = Ms{config.delay_ms};
      } else {
        delay_left_ -= elapsed;
        if (delay_left_ <= Ms{0}) {
          commanded_on_ = requested_on_;
          delay_running_ = false;
        }
      }
      break;
    }
  }
  present_ = target_ = commanded_on_ ? 1.0 : 0.0;
}

void OutputDrive::Drive(Ms elapsed, const DriveConfig& config, const LoadModel& load) {
  const OutputType type = config.type;
  const double scale = blocks::PowerOfTen(config.fv_digits);
  const double vps = std::max(0.0, load.supply_V);
  const double ohm = std::max(load.resistance_ohm, 1e-3);

  // Hotshot phase (Figure 5): restarts at every OFF->ON of the driver command.
  const bool hotshot_on = type == OutputType::kHotshot && commanded_on_;
  if (!hotshot_on) {
    hotshot_running_ = false;
  } else if (!hotshot_running_ && !out_.driving) {
    hotshot_running_ = true;
    hotshot_left_ = kHotshotTime;
  } else if (hotshot_running_) {
    hotshot_left_ -= elapsed;
    if (hotshot_left_ <= Ms{0}) hotshot_running_ = false;
  }

  DriveOutput out;
  out.target_fv = IsDigital(type) ? (requested_on_ ? 1.0 : 0.0) : target_;
  double duty = 0.0;  // 0..1 of Vps while driving a voltage-driven type
  switch (type) {
    case OutputType::kCurrent:
      out.desired_mA = std::max(0.0, present_ / scale);
      out.driving = out.desired_mA > 0.0;
      break;
    case OutputType::kHotshot:
      out.desired_mA = commanded_on_ ? (hotshot_running_ ? kHotshotCurrent_mA : kHoldCurrent_mA) : 0.0;
      out.driving = commanded_on_;
      break;
    case OutputType::kVoltage:
      duty = vps > 0.0 ? std::clamp(present_ / scale / vps, 0.0, 1.0) : 0.0;
      out.driving = present_ > 0.0;
      break;
    case OutputType::kPwm:
      duty = std::clamp(present_ / scale / 100.0, 0.0, 1.0);
      out.driving = duty > 0.0;
      break;
    case OutputType::kDigital:
      duty = commanded_on_ ? 1.0 : 0.0;
      out.driving = commanded_on_;
      break;
    case OutputType::kDisabled:
      break;
  }

  // Short-circuit protection (1.5, 4.3): off, then a retry every kRetryPeriod while commanded.
  if (!out.driving) {
    tripped_ = false;
  } else if (tripped_) {
    retry_left_ -= elapsed;
    if (retry_left_ <= Ms{0}) tripped_ = false;  // re-engage: tried again below
  }
  if (out.driving && !tripped_) {
    const bool switched = !IsCurrentControlled(type);
    const bool over_current =
        switched && load.load == LoadState::kNominal && vps / ohm * 1000.0 > kTripCurrent_mA;
    if (load.load == LoadState::kShort || over_current) {
      tripped_ = true;
      retry_left_ = kRetryPeriod;
    }
  }
  out.tripped = tripped_;
  out.hotshot = hotshot_running_ && out.driving && !tripped_;

  if (out.driving && !tripped_) {
    out.on = true;
    out.frequency_Hz = type == OutputType::kPwm       ? load.pwm_frequency_Hz
                       : type == OutputType::kDigital ? 0.0
                                                      : kDriverFrequency_Hz;
    if (IsCurrentControlled(type)) {
      if (load.load == LoadState::kOpen) {
        out.duty_pct = 100.0;  // the regulator opens fully and finds no current
        out.voltage_V = vps;
      } else {
        out.current_mA = std::min(out.desired_mA, vps / ohm * 1000.0);
        out.voltage_V = out.current_mA / 1000.0 * ohm;
        out.duty_pct = vps > 0.0 ? std::min(100.0, out.voltage_V / vps * 100.0) : 0.0;
      }
      if (type == OutputType::kHotshot) out.frequency_Hz = kDriverFrequency_Hz;
    } else {
      out.duty_pct = duty * 100.0;
      out.voltage_V = duty * vps;
      out.current_mA = load.load == LoadState::kOpen ? 0.0 : out.voltage_V / ohm * 1000.0;
    }
  }
  out_ = out;
}

std::optional<OutputDrive::Ms> OutputDrive::NextChange() const {
  std::optional<Ms> next;
  if (ramping_) next = kTick;
  if (delay_running_) next = MinOpt(next, std::max(kTick, delay_left_));
  if (hotshot_running_) next = MinOpt(next, std::max(kTick, hotshot_left_));
  if (tripped_) next = MinOpt(next, std::max(kTick, retry_left_));
  return next;
}

}  // namespace canfleet::devices::encoder
