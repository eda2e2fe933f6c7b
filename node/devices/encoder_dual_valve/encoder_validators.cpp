#include "node/devices/encoder_dual_valve/encoder_validators.hpp"

#include <algorithm>
#include <memory>
#include <vector>

#include "node/devices/encoder_dual_valve/encoder_objects.hpp"
#include "node/devices/encoder_dual_valve/input_defaults.hpp"
#include "node/devices/od_ref.hpp"

namespace canfleet::devices::encoder {
namespace {

using canopen::ObjectDictionary;
using canopen::Origin;
using canopen::SdoAbort;
using canopen::SubObject;

std::int64_t Decode(const SubObject& sub, std::span<const std::uint8_t> data) {
  if (canopen::IsSigned(sub.type)) return canopen::DecodeSignedLe(data);
  return static_cast<std::int64_t>(canopen::DecodeUnsignedLe(data));
}

SubObject& Entry(ObjectDictionary& od, std::uint16_t index, std::uint8_t sub) {
  return OdRef(od, index, sub).sub();
}

void AllowOnly(SubObject& sub, std::vector<std::int64_t> allowed) {
  sub.AddValidator(
      [allowed = std::move(allowed)](const SubObject& s, std::span<const std::uint8_t> data, Origin) {
        return std::find(allowed.begin(), allowed.end(), Decode(s, data)) != allowed.end()
                   ? SdoAbort::kNone
                   : SdoAbort::kInvalidValue;
      });
}

void Between(SubObject& sub, std::int64_t low, std::int64_t high) {
  sub.AddValidator([low, high](const SubObject& s, std::span<const std::uint8_t> data, Origin) {
    const auto v = Decode(s, data);
    if (v < low) return SdoAbort::kValueTooLow;
    if (v > high) return SdoAbort::kValueTooHigh;
    return SdoAbort::kNone;
  });
}

void OnNetworkWrite(SubObject& sub, std::function<void()> action) {
  sub.AddListener([action = std::move(action)](SubObject&, Origin origin) {
    if (origin != Origin::kDevice) action();
  });
}

/// One (source, number) pair of objects.
struct Pair {
  std::uint16_t source_index;
  std::uint8_t source_sub;
  std::uint16_t number_index;
  std::uint8_t number_sub;
};

void InstallPair(ObjectDictionary& od, const blocks::ControlSources& sources, const Pair& p) {
  ObjectDictionary* dict = &od;
  const blocks::ControlSources* table = &sources;
  Entry(od, p.source_index, p.source_sub)
      .AddValidator([dict, table, p](const SubObject& s, std::span<const std::uint8_t> data, Origin) {
        const auto code = static_cast<std::uint8_t>(Decode(s, data));
        if (!table->IsSourceAllowed(code)) return SdoAbort::kValueTooHigh;
        const auto number = static_cast<std::uint8_t>(dict->GetUnsigned(p.number_index, p.number_sub));
        return table->IsAllowed({code, number}) ? SdoAbort::kNone : SdoAbort::kParameterIncompatible;
      });
  Entry(od, p.number_index, p.number_sub)
      .AddValidator([dict, table, p](const SubObject& s, std::span<const std::uint8_t> data, Origin) {
        const auto code = static_cast<std::uint8_t>(dict->GetUnsigned(p.source_index, p.source_sub));
        const blocks::SourceType* type = table->Find(code);
        if (!type || type->number_ignored) return SdoAbort::kNone;
        const auto number = Decode(s, data);
        if (number < type->first_number) return SdoAbort::kValueTooLow;
        if (number > type->last_number) return SdoAbort::kValueTooHigh;
        return SdoAbort::kNone;
      });
}

struct OutputDefaults {
  std::int64_t digits, pv1, fv1, pv2, fv2, fault_fv;
};

std::optional<OutputDefaults> OutputDefaultsFor(OutputType type) {
  switch (type) {
    case OutputType::kCurrent:
      return OutputDefaults{0, 0, 0, 5000, 5000, 500};  // the printed defaults (C3-1.3.26-1.3.31)
    case OutputType::kVoltage:
      return OutputDefaults{1, 0, 0, 600, 600, 0};  // 0.1 V (4.3)
    case OutputType::kPwm:
      return OutputDefaults{1, 0, 0, 1000, 1000, 0};  // 0.1 % (4.3)
    case OutputType::kDigital:
    case OutputType::kHotshot:
      return OutputDefaults{0, 0, 0, 1, 1, 0};
    case OutputType::kDisabled:
      break;
  }
  return std::nullopt;
}

}  // namespace

void ApplyInputDefaults(ObjectDictionary& od, int ch) {
  const std::uint8_t sub = SubOf(ch);
  const auto row = InputDefaultsFor(static_cast<std::uint16_t>(od.GetUnsigned(kAiSensorType, sub)),
                                    static_cast<std::uint8_t>(od.GetUnsigned(kAiOperatingMode, sub)),
                                    static_cast<std::uint8_t>(od.GetUnsigned(kAiRange, sub)));
  if (!row) return;
  OdRef(od, kAiFvDigits, sub).Set(row->fv_digits);
  OdRef(od, kAiSpanStart, sub).Set(row->span_start);
  OdRef(od, kAiScaling1Fv, sub).Set(row->scaling1);
  OdRef(od, kAiScaling1Pv, sub).Set(row->scaling1);
  OdRef(od, kAiScaling2Fv, sub).Set(row->scaling2);
  OdRef(od, kAiScaling2Pv, sub).Set(row->scaling2);
  OdRef(od, kAiSpanEnd, sub).Set(row->span_end);
  OdRef(od, kAiErrorHysteresis, sub).Set(row->hysteresis);
}

void ApplyOutputDefaults(ObjectDictionary& od, int n) {
  const std::uint8_t sub = SubOf(n);
  const auto row = OutputDefaultsFor(static_cast<OutputType>(od.GetUnsigned(kAoOutputType, sub)));
  if (!row) return;
  OdRef(od, kAoFvDigits, sub).Set(row->digits);
  OdRef(od, kAoPvDigits, sub).Set(row->digits);
  OdRef(od, kAoScaling1Pv, sub).Set(row->pv1);
  OdRef(od, kAoScaling1Fv, sub).Set(row->fv1);
  OdRef(od, kAoScaling2Pv, sub).Set(row->pv2);
  OdRef(od, kAoScaling2Fv, sub).Set(row->fv2);
  OdRef(od, kAoFaultFv, sub).Set(row->fault_fv);
  OdRef(od, kAoOverrideFv, sub).Set(0);
}

void InstallEncoderValidators(canopen::CanopenStack& stack, const blocks::ControlSources& sources,
                              std::function<void(int ch)> on_input_reconfigured) {
  ObjectDictionary& od = stack.od();
  ObjectDictionary* dict = &od;
  auto reconfigured = std::make_shared<std::function<void(int)>>(std::move(on_input_reconfigured));

  for (int ch = 0; ch < kInputs; ++ch) {
    const std::uint8_t sub = SubOf(ch);
    AllowOnly(Entry(od, kAiSensorType, sub), {60, 10000, 10002});
    AllowOnly(Entry(od, kAiOperatingMode, sub), {0, 1, 10});
    Entry(od, kAiRange, sub)
        .AddValidator([dict, sub](const SubObject& s, std::span<const std::uint8_t> data, Origin) {
          const auto max = MaxRange(static_cast<std::uint16_t>(dict->GetUnsigned(kAiSensorType, sub)),
                                    static_cast<std::uint8_t>(dict->GetUnsigned(kAiOperatingMode, sub)));
          return Decode(s, data) > max ? SdoAbort::kValueTooHigh : SdoAbort::kNone;
        });
    OnNetworkWrite(Entry(od, kAiSensorType, sub), [dict, ch, sub, reconfigured] {
      OdRef(*dict, kAiRange, sub).Set(0);
      ApplyInputDefaults(*dict, ch);
      if (*reconfigured) (*reconfigured)(ch);
    });
    OnNetworkWrite(Entry(od, kAiRange, sub), [dict, ch, reconfigured] {
      ApplyInputDefaults(*dict, ch);
      if (*reconfigured) (*reconfigured)(ch);
    });
    OnNetworkWrite(Entry(od, kAiOperatingMode, sub), [dict, ch, sub, reconfigured] {
      const auto max = MaxRange(static_cast<std::uint16_t>(dict->GetUnsigned(kAiSensorType, sub)),
                                static_cast<std::uint8_t>(dict->GetUnsigned(kAiOperatingMode, sub)));
      if (dict->GetUnsigned(kAiRange, sub) > max) OdRef(*dict, kAiRange, sub).Set(0);
      ApplyInputDefaults(*dict, ch);
      if (*reconfigured) (*reconfigured)(ch);
    });
  }

  for (int n = 0; n < kOutputs; ++n) {
    const std::uint8_t sub = SubOf(n);
    AllowOnly(Entry(od, kAoOutputType, sub), {0, 10, 20, 40, 1000, 1020});
    OnNetworkWrite(Entry(od, kAoOutputType, sub), [dict, n] { ApplyOutputDefaults(*dict, n); });
    InstallPair(od, sources, {kAoControlSource, sub, kAoControlNumber, sub});
    InstallPair(od, sources, {kAoEnableSource, sub, kAoEnableNumber, sub});
    InstallPair(od, sources, {kAoOverrideSource, sub, kAoOverrideNumber, sub});
  }
  for (int t = 1; t <= kLookupTables; ++t)
    InstallPair(od, sources, {LutIndex(t, kLutSource), 0, LutIndex(t, kLutNumber), 0});
  for (int m = 1; m <= kMathBlocks; ++m) {
    for (std::uint8_t i = 1; i <= kMathInputs; ++i) {
      InstallPair(od, sources, {MathIndex(m, kMathSource), i, MathIndex(m, kMathNumber), i});
      Between(Entry(od, MathIndex(m, kMathGain), i), -100, 100);
    }
  }
  InstallPair(od, sources, {kPidTargetSource, 0, kPidTargetNumber, 0});
  InstallPair(od, sources, {kPidFeedbackSource, 0, kPidFeedbackNumber, 0});

  // 1.8: setpoint control locks the target to a control constant.
  Entry(od, kPidTargetSource, 0)
      .AddValidator([dict](const SubObject& s, std::span<const std::uint8_t> data, Origin) {
        const bool setpoint = dict->GetUnsigned(kPidResponse, 0) == 1;
        return setpoint && Decode(s, data) != 9 ? SdoAbort::kDeviceState : SdoAbort::kNone;
      });
  OnNetworkWrite(Entry(od, kPidResponse, 0), [dict] {
    if (dict->GetUnsigned(kPidResponse, 0) != 1) return;
    OdRef(*dict, kPidTargetSource, 0).Set(9);
    const auto number = dict->GetUnsigned(kPidTargetNumber, 0);
    if (number < 1 || number > 12) OdRef(*dict, kPidTargetNumber, 0).Set(1);
  });

  Between(Entry(od, kQdPulsesPerRev, 0), 1, 0x7FFFFFFF);

  // 1.5: "Sub-index 1 is fixed as FALSE (0) and sub-index 2 is always TRUE (1)".
  for (std::uint8_t sub : {std::uint8_t{1}, std::uint8_t{2}}) {
    SubObject& constant = Entry(od, kConstants, sub);
    constant.AddValidator(
        [fixed = constant.default_value](const SubObject&, std::span<const std::uint8_t> data, Origin) {
          return std::equal(data.begin(), data.end(), fixed.begin(), fixed.end()) ? SdoAbort::kNone
                                                                                  : SdoAbort::kInvalidValue;
        });
  }
}

}  // namespace canfleet::devices::encoder
