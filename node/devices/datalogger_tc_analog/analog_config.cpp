#include "node/devices/datalogger_tc_analog/analog_config.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include "node/devices/blocks/signal.hpp"
#include "node/devices/datalogger_tc_analog/datalogger_objects.hpp"
#include "node/devices/od_ref.hpp"

namespace canfleet::devices::datalogger {

namespace {

using blocks::InputRange;
using canopen::ObjectDictionary;
using canopen::Origin;
using canopen::SdoAbort;
using canopen::SubObject;

std::int64_t Decode(const SubObject& sub, std::span<const std::uint8_t> data) {
  if (canopen::IsSigned(sub.type)) return canopen::DecodeSignedLe(data);
  return static_cast<std::int64_t>(canopen::DecodeUnsignedLe(data));
}

std::int64_t ValueOf(const ObjectDictionary& od, std::uint16_t index, std::uint8_t sub) {
  const SubObject* s = od.Find(index, sub);
  if (!s) return 0;
  return canopen::IsSigned(s->type) ? canopen::DecodeSignedLe(s->value)
                                    : static_cast<std::int64_t>(canopen::DecodeUnsignedLe(s->value));
}

SubObject& Entry(ObjectDictionary& od, std::uint16_t index, std::uint8_t sub) {
  return OdRef(od, index, sub).sub();
}

void Validate(ObjectDictionary& od, std::uint16_t index, std::uint8_t sub,
              std::function<SdoAbort(std::int64_t value)> check) {
  Entry(od, index, sub)
      .AddValidator([check = std::move(check)](const SubObject& s, std::span<const std::uint8_t> data,
                                               Origin) { return check(Decode(s, data)); });
}

// Input number (1-based) of channel `ch`.
int InputOf(int ch) {
  return ch + 1;
}

// MAX of Table 12 in field-value units, and the 4-20 mA / frequency minimum of 7120h.
struct FvLimits {
  double max = 32767;
  double scaling1_min = 0;
};

FvLimits LimitsOf(const ObjectDictionary& od, int ch) {
  FvLimits limits;
  const auto range = ClassifyChannel(od, ch);
  if (!range) return limits;
  const double scale = blocks::PowerOfTen(static_cast<std::uint8_t>(ValueOf(od, kAiFvDigits, SubOf(ch))));
  limits.max = FullScale(*range) * scale;
  if (*range == InputRange::kCurrent4To20mA) limits.scaling1_min = 4 * scale;
  if (*range == InputRange::kFrequency) limits.scaling1_min = std::ceil(0.5 * scale);
  return limits;
}

SdoAbort Within(double value, double low, double high) {
  if (value < low) return SdoAbort::kValueTooLow;
  if (value > high) return SdoAbort::kValueTooHigh;
  return SdoAbort::kNone;
}

}  // namespace

std::optional<InputRange> ClassifyChannel(const ObjectDictionary& od, int ch) {
  const std::uint8_t sub = SubOf(ch);
  return blocks::ClassifyInput(static_cast<std::uint16_t>(ValueOf(od, kSensorType, sub)),
                               static_cast<std::uint8_t>(ValueOf(od, kAiRange, sub)),
                               ValueOf(od, kAiPulsesPerRev, sub) != 0,
                               ValueOf(od, kAiOperatingMode, sub) == kModeDigital);
}

double FullScale(InputRange range) {
  switch (range) {
    case InputRange::kVoltage0To5V:
      return 5;
    case InputRange::kVoltage0To10V:
      return 10;
    case InputRange::kCurrent0To20mA:
    case InputRange::kCurrent4To20mA:
      return 20;
    case InputRange::kFrequency:
      return 50000;
    case InputRange::kRpm:
      return 3000;  // Table 11's 7122h = 30000 [0.1 rpm]; its 7149h 33000 is exactly 110 % of it
    case InputRange::kPwm:
      return 100;
    case InputRange::kDigital:
      return 1;
    case InputRange::kResistive:
      break;
  }
  return 32767;
}

void ApplyInputDefaults(ObjectDictionary& od, int ch, InputRange range) {
  const auto row = blocks::FindInputDefaults(blocks::DataLoggerInputDefaults(), range);
  if (!row) return;
  const std::uint8_t sub = SubOf(ch);
  OdRef(od, kAiFvDigits, sub).Set(row->fv_digits);
  OdRef(od, kAiSpanStart, sub).Set(row->span_start);
  OdRef(od, kAiScaling1Fv, sub).Set(row->scaling1);
  OdRef(od, kAiScaling2Fv, sub).Set(row->scaling2);
  OdRef(od, kAiSpanEnd, sub).Set(row->span_end);
  OdRef(od, kAiErrorHysteresis, sub).Set(row->hysteresis);
}

void InstallAnalogValidators(ObjectDictionary& od) {
  ObjectDictionary* dict = &od;  // the hooks outlive this function
  for (int ch = 0; ch < kAnalogInputs; ++ch) {
    const std::uint8_t sub = SubOf(ch);
    const int input = InputOf(ch);
    const bool universal = input >= kFirstUniversal;
    const bool pulse = input == 8 || input == 9;

    Validate(od, kAiOperatingMode, sub, [universal](std::int64_t v) {
      const bool ok =
          v == kModeOff || v == kModeNormal || v == kModeAnalogOnOff || (universal && v == kModeDigital);
      return ok ? SdoAbort::kNone : SdoAbort::kInvalidValue;
    });
    Validate(od, kSensorType, sub, [pulse](std::int64_t v) {
      const bool ok =
          v == kSensorVoltage || v == kSensorCurrent || (pulse && (v == kSensorFrequency || v == kSensorPwm));
      return ok ? SdoAbort::kNone : SdoAbort::kInvalidValue;
    });
    Validate(od, kAiRange, sub, [dict, sub, input](std::int64_t v) {
      std::int64_t highest = 0;
      switch (ValueOf(*dict, kSensorType, sub)) {
        case kSensorVoltage:
          highest = input < kFirstUniversal ? 1 : 0;  // "0-10V will only be available for Input 1-7"
          break;
        case kSensorCurrent:
          highest = 1;
          break;
        default:
          highest = 0;
      }
      return v > highest ? SdoAbort::kValueTooHigh : SdoAbort::kNone;
    });
    Validate(od, kAiFvDigits, sub, [dict](std::int64_t) {
      return ValueOf(*dict, kAutoUpdates, 0) != 0 ? SdoAbort::kDeviceState : SdoAbort::kNone;
    });
    if (!universal) {
      for (std::uint16_t index : {kDiPolarity, kDiPullup})
        Validate(od, index, sub,
                 [](std::int64_t v) { return v == 0 ? SdoAbort::kNone : SdoAbort::kInvalidValue; });
    }

    // Table 12, with the other objects as they are now.
    Validate(od, kAiSpanStart, sub, [dict, sub](std::int64_t v) {
      return Within(static_cast<double>(v), 0, static_cast<double>(ValueOf(*dict, kAiScaling1Fv, sub)));
    });
    Validate(od, kAiScaling1Fv, sub, [dict, ch, sub](std::int64_t v) {
      const FvLimits limits = LimitsOf(*dict, ch);
      const double low =
          std::max(static_cast<double>(ValueOf(*dict, kAiSpanStart, sub)), limits.scaling1_min);
      return Within(static_cast<double>(v), low, static_cast<double>(ValueOf(*dict, kAiScaling2Fv, sub)));
    });
    Validate(od, kAiScaling2Fv, sub, [dict, ch, sub](std::int64_t v) {
      return Within(static_cast<double>(v), static_cast<double>(ValueOf(*dict, kAiScaling1Fv, sub)),
                    LimitsOf(*dict, ch).max);
    });
    Validate(od, kAiSpanEnd, sub, [dict, ch, sub](std::int64_t v) {
      return Within(static_cast<double>(v), static_cast<double>(ValueOf(*dict, kAiScaling2Fv, sub)),
                    std::floor(1.1 * LimitsOf(*dict, ch).max));
    });
    Validate(od, kAiErrorHysteresis, sub, [dict, ch](std::int64_t v) {
      return Within(static_cast<double>(v), 0, std::floor(0.1 * LimitsOf(*dict, ch).max));
    });
  }
}

}  // namespace canfleet::devices::datalogger
