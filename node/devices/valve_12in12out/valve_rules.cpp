#include "node/devices/valve_12in12out/valve_rules.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include "node/devices/blocks/control_source.hpp"
#include "node/devices/blocks/signal.hpp"
#include "node/devices/od_ref.hpp"
#include "node/devices/valve_12in12out/input_ranges.hpp"

namespace canfleet::devices::valve {

namespace {

using canopen::ObjectDictionary;
using canopen::Origin;
using canopen::SdoAbort;
using canopen::SubObject;

std::int64_t Decode(const SubObject& sub, std::span<const std::uint8_t> data) {
  if (canopen::IsSigned(sub.type)) return canopen::DecodeSignedLe(data);
  return static_cast<std::int64_t>(canopen::DecodeUnsignedLe(data));
}

std::int64_t Value(const ObjectDictionary& od, std::uint16_t index, std::uint8_t sub) {
  const SubObject* s = od.Find(index, sub);
  if (!s) return 0;
  return canopen::IsSigned(s->type) ? canopen::DecodeSignedLe(s->value)
                                    : static_cast<std::int64_t>(canopen::DecodeUnsignedLe(s->value));
}

SubObject& Entry(ObjectDictionary& od, std::uint16_t index, std::uint8_t sub) {
  return OdRef(od, index, sub).sub();
}

/// A rule on the value as it would be after the write.
void Check(ObjectDictionary& od, std::uint16_t index, std::uint8_t sub,
           std::function<SdoAbort(std::int64_t)> rule) {
  Entry(od, index, sub)
      .AddValidator([rule = std::move(rule)](const SubObject& s, std::span<const std::uint8_t> data, Origin) {
        return rule(Decode(s, data));
      });
}

/// [low, high] with the abort code for each side.
SdoAbort Within(double v, double low, double high) {
  if (v < low) return SdoAbort::kValueTooLow;
  if (v > high) return SdoAbort::kValueTooHigh;
  return SdoAbort::kNone;
}

/// After an SDO (or PDO) write only: the device's own writes and stored values never cascade.
void OnWrite(ObjectDictionary& od, std::uint16_t index, std::uint8_t sub, std::function<void()> action) {
  Entry(od, index, sub).AddListener([action = std::move(action)](SubObject&, Origin origin) {
    if (origin != Origin::kDevice) action();
  });
}

double Pow10(std::int64_t digits) {
  return blocks::PowerOfTen(static_cast<std::uint8_t>(std::clamp<std::int64_t>(digits, 0, 4)));
}

/// The largest FV of an output type in its FV units (§4 "0 - Imax (2.5A)", Table 14), nullopt for
/// a disabled output (nothing to check).
std::optional<double> OutputMax(std::int64_t type, std::int64_t fv_digits) {
  switch (static_cast<OutputType>(type)) {
    case OutputType::kCurrent:
      return 2500 * Pow10(fv_digits);
    case OutputType::kVoltage:
      return 24000 * Pow10(fv_digits);
    case OutputType::kPwm:
      return 100 * Pow10(fv_digits);
    case OutputType::kDigital:
    case OutputType::kHotshot:
      return 1;
    case OutputType::kDisabled:
      break;
  }
  return std::nullopt;
}

}  // namespace

ValveRules::ValveRules(canopen::CanopenStack& stack) : od_(stack.od()) {
  for (int ch = 0; ch < kInputs; ++ch)
    InstallInputRules(ch);
  for (int ch = 0; ch < kOutputs; ++ch)
    InstallOutputRules(ch);
  InstallSourceRules();
  for (int t = 1; t <= kLookupTables; ++t)
    InstallLookupTableRules(t);
  InstallMiscRules();
  Resync();
}

bool ValveRules::AutoUpdate() const {
  return Value(od_, kAutoUpdate, 0) != 0;
}

std::optional<blocks::InputRange> ValveRules::ClassOf(int ch) const {
  const std::uint8_t sub = SubOf(ch);
  return ClassifyValveInput(static_cast<std::uint16_t>(Value(od_, kAiSensorType, sub)),
                            static_cast<std::uint8_t>(Value(od_, kAiRange, sub)),
                            static_cast<std::uint16_t>(Value(od_, kAiPulsesPerRev, sub)),
                            static_cast<std::uint8_t>(Value(od_, kAiMode, sub)));
}

void ValveRules::Resync() {
  for (int ch = 0; ch < kInputs; ++ch) {
    loaded_[ch] = ClassOf(ch);
    sensor_type_[ch] = Value(od_, kAiSensorType, SubOf(ch));
  }
  for (int ch = 0; ch < kOutputs; ++ch)
    output_type_[ch] = Value(od_, kAoType, SubOf(ch));
}

void ValveRules::LoadInputDefaults(int ch, bool force) {
  const auto now = ClassOf(ch);
  const bool changed = force || now != loaded_[ch];
  loaded_[ch] = now;
  if (!changed || !now || !AutoUpdate()) return;
  const blocks::InputDefaults row = ValveDefaultsFor(*now);
  const std::uint8_t sub = SubOf(ch);
  const auto set = [this, sub](std::uint16_t index, double value) {
    OdRef(od_, index, sub).SetNumber(value);
  };
  set(kAiFvDigits, row.fv_digits);
  set(kAiSpanStart, row.span_start);
  set(kAiScaling1Fv, row.scaling1);
  set(kAiScaling2Fv, row.scaling2);
  set(kAiSpanEnd, row.span_end);
  set(kAiErrorHysteresis, row.hysteresis);
  // "the default relationship between the FV and PV is one-to-one" (§1.3).
  set(kAiScaling1Pv, row.scaling1);
  set(kAiScaling2Pv, row.scaling2);
  set(kAiPvDigits, row.fv_digits);
}

void ValveRules::InstallInputRules(int ch) {
  ObjectDictionary& od = od_;
  ObjectDictionary* dict = &od_;
  const std::uint8_t sub = SubOf(ch);
  Check(od, kAiSensorType, sub, [ch](std::int64_t v) {
    return SensorTypeAllowed(ch, static_cast<std::uint16_t>(v)) ? SdoAbort::kNone : SdoAbort::kInvalidValue;
  });
  Check(od, kAiMode, sub, [ch](std::int64_t v) {
    return InputModeAllowed(ch, static_cast<std::uint8_t>(v)) ? SdoAbort::kNone : SdoAbort::kInvalidValue;
  });
  Check(od, kAiRange, sub, [dict, sub](std::int64_t v) {
    const auto type = static_cast<std::uint16_t>(Value(*dict, kAiSensorType, sub));
    return InputRangeAllowed(type, static_cast<std::uint8_t>(v)) ? SdoAbort::kNone : SdoAbort::kInvalidValue;
  });
  // §3.4.6: "normally read-only ... When object 5550h is set to FALSE, this object becomes writeable."
  Check(od, kAiFvDigits, sub,
        [this](std::int64_t) { return AutoUpdate() ? SdoAbort::kDeviceState : SdoAbort::kNone; });

  // Table 11, in the FV units of the current 2102h.
  const auto bounds = [this, ch]() -> std::optional<InputBounds> {
    const auto cls = ClassOf(ch);
    if (!cls) return std::nullopt;
    return BoundsFor(*cls, static_cast<std::uint8_t>(Value(od_, kAiFvDigits, SubOf(ch))));
  };
  const auto value = [dict, sub](std::uint16_t index) {
    return static_cast<double>(Value(*dict, index, sub));
  };
  Check(od, kAiSpanStart, sub, [bounds, value](std::int64_t v) {
    const auto b = bounds();
    return b ? Within(static_cast<double>(v), b->span_start_low, value(kAiScaling1Fv)) : SdoAbort::kNone;
  });
  Check(od, kAiScaling1Fv, sub, [bounds, value](std::int64_t v) {
    const auto b = bounds();
    if (!b) return SdoAbort::kNone;
    return Within(static_cast<double>(v), std::max(value(kAiSpanStart), b->scaling1_floor),
                  value(kAiScaling2Fv));
  });
  Check(od, kAiScaling2Fv, sub, [bounds, value](std::int64_t v) {
    const auto b = bounds();
    if (!b) return SdoAbort::kNone;
    return Within(static_cast<double>(v), value(kAiScaling1Fv), std::min(value(kAiSpanEnd), b->max));
  });
  Check(od, kAiSpanEnd, sub, [bounds, value](std::int64_t v) {
    const auto b = bounds();
    return b ? Within(static_cast<double>(v), value(kAiScaling2Fv), b->span_end_high) : SdoAbort::kNone;
  });
  Check(od, kAiErrorHysteresis, sub, [bounds](std::int64_t v) {
    const auto b = bounds();
    return b ? Within(static_cast<double>(v), 0, b->hysteresis_high) : SdoAbort::kNone;
  });

  // 5550h: the Table 10 cascade.
  OnWrite(od, kAiSensorType, sub, [this, ch, sub] {
    const auto now = Value(od_, kAiSensorType, sub);
    const bool changed = now != sensor_type_[ch];
    sensor_type_[ch] = now;
    if (changed && AutoUpdate()) {
      OdRef(od_, kAiRange, sub).Set(0);  // Table 6: the type's default range
      // §1.3: "voltage, current and resistive inputs set this object [2020h] to zero".
      const auto type = static_cast<SensorType>(now);
      if (type == SensorType::kVoltage || type == SensorType::kCurrent || type == SensorType::kResistive)
        OdRef(od_, kDiPull, sub).Set(0);
    }
    LoadInputDefaults(ch, changed);
  });
  for (std::uint16_t index : {kAiRange, kAiMode, kAiPulsesPerRev})
    OnWrite(od, index, sub, [this, ch] { LoadInputDefaults(ch, false); });
}

void ValveRules::LoadOutputDefaults(int ch) {
  if (!AutoUpdate()) return;
  const std::uint8_t sub = SubOf(ch);
  const auto type = static_cast<OutputType>(Value(od_, kAoType, sub));
  double min = 0;
  double max = 1;
  int pv_digits = 0;
  int fv_digits = 0;
  switch (type) {
    case OutputType::kDisabled:
      return;
    case OutputType::kCurrent:
      min = 300, max = 1500, pv_digits = 3;
      break;
    case OutputType::kVoltage:
      min = 5000, max = 24000, pv_digits = 3;
      break;
    case OutputType::kPwm:
      min = 100, max = 900, pv_digits = 1, fv_digits = 1;
      break;
    case OutputType::kDigital:
    case OutputType::kHotshot:
      break;
  }
  const auto set = [this, sub](std::uint16_t index, double value) {
    OdRef(od_, index, sub).SetNumber(value);
  };
  set(kAoPvDigits, pv_digits);
  set(kAoFvDigits, fv_digits);
  set(kAoScaling1Pv, min);
  set(kAoScaling1Fv, min);
  set(kAoScaling2Pv, max);
  set(kAoScaling2Fv, max);
  if (type == OutputType::kCurrent) {
    set(kAoFaultFv, 500);
    set(kAoOverrideFv, 750);
  } else {
    for (std::uint16_t index : {kAoFaultFv, kAoOverrideFv})
      set(index, std::clamp(static_cast<double>(Value(od_, index, sub)), min, max));
  }
}

void ValveRules::InstallOutputRules(int ch) {
  ObjectDictionary& od = od_;
  ObjectDictionary* dict = &od_;
  const std::uint8_t sub = SubOf(ch);
  Check(od, kAoType, sub, [ch](std::int64_t v) {
    const auto t = static_cast<OutputType>(v);
    const bool ok =
        ch < kProportionalOutputs
            ? (t == OutputType::kDisabled || t == OutputType::kVoltage || t == OutputType::kCurrent ||
               t == OutputType::kPwm || t == OutputType::kDigital || t == OutputType::kHotshot)
            : (t == OutputType::kDisabled || t == OutputType::kDigital);  // §1.4: DO1-4 only 0 or 1000
    return ok ? SdoAbort::kNone : SdoAbort::kInvalidValue;
  });
  // The listener sees the new type only: the old one is kept here.
  OnWrite(od, kAoType, sub, [this, ch, sub] {
    const auto now = Value(od_, kAoType, sub);
    const bool changed = now != output_type_[ch];
    output_type_[ch] = now;
    if (changed) LoadOutputDefaults(ch);
  });

  const auto value = [dict, sub](std::uint16_t index) { return Value(*dict, index, sub); };
  // §3.3.24/3.3.26: 7320h must always be smaller than 7322h.
  Check(od, kAoScaling1Pv, sub, [value](std::int64_t v) {
    return v >= value(kAoScaling2Pv) ? SdoAbort::kValueTooHigh : SdoAbort::kNone;
  });
  Check(od, kAoScaling2Pv, sub, [value](std::int64_t v) {
    return v <= value(kAoScaling1Pv) ? SdoAbort::kValueTooLow : SdoAbort::kNone;
  });
  // "Dependent on type (see Table 14)".
  for (std::uint16_t index : {kAoScaling1Fv, kAoScaling2Fv, kAoFaultFv, kAoOverrideFv}) {
    Check(od, index, sub, [value](std::int64_t v) {
      const auto max = OutputMax(value(kAoType), value(kAoFvDigits));
      return max ? Within(static_cast<double>(v), 0, *max) : SdoAbort::kNone;
    });
  }
  // §3.4.28: "0 to 10% of 7321h or 7323h, whichever is larger".
  Check(od, kAoErrorTolerance, sub, [value](std::int64_t v) {
    const double larger =
        static_cast<double>(std::max(std::abs(value(kAoScaling1Fv)), std::abs(value(kAoScaling2Fv))));
    return Within(static_cast<double>(v), 0, std::floor(larger * 0.1));
  });
  // §3.4.20/3.4.21: hold <= hotshot <= Imax (2.5 A), in 6332h units.
  Check(od, kDoHotshotCurrent, sub, [value](std::int64_t v) {
    return Within(static_cast<double>(v), static_cast<double>(value(kDoHoldCurrent)),
                  2500 * Pow10(value(kAoFvDigits)));
  });
  Check(od, kDoHoldCurrent, sub, [value](std::int64_t v) {
    return Within(static_cast<double>(v), 0, static_cast<double>(value(kDoHotshotCurrent)));
  });
}

void ValveRules::InstallSourceRules() {
  ObjectDictionary& od = od_;
  ObjectDictionary* dict = &od_;
  // Table 16: the number must fit the source set now.
  const auto number_rule = [dict](std::uint16_t source_index, std::uint8_t source_sub) {
    return [dict, source_index, source_sub](std::int64_t v) {
      static const blocks::ControlSources table(blocks::ValveSourceTypes(), nullptr);
      const auto* type = table.Find(static_cast<std::uint8_t>(Value(*dict, source_index, source_sub)));
      if (!type || type->number_ignored) return SdoAbort::kNone;
      return Within(static_cast<double>(v), type->first_number, type->last_number);
    };
  };
  const auto pair = [&](std::uint16_t source, std::uint16_t number, std::uint8_t first_sub,
                        std::uint8_t last_sub) {
    for (int s = first_sub; s <= last_sub; ++s) {
      const auto sub = static_cast<std::uint8_t>(s);
      Check(od, number, sub, number_rule(source, sub));
    }
  };
  pair(kAoControlSource, kAoControlNumber, 1, kOutputs);
  pair(kAoEnableSource, kAoEnableNumber, 1, kOutputs);
  pair(kAoOverrideSource, kAoOverrideNumber, 1, kOutputs);
  pair(kPidTargetSource, kPidTargetNumber, 1, kPids);
  pair(kPidFeedbackSource, kPidFeedbackNumber, 1, kPids);
  for (int t = 1; t <= kLookupTables; ++t)
    Check(od, LutIndex(t, 1), 0, number_rule(LutIndex(t, 0), 0));
  for (int y = 1; y <= kMathBlocks; ++y)
    pair(MathIndex(y, kMathInSource), MathIndex(y, kMathInNumber), 1, 6);
  for (int b = 1; b <= kLogicBlocks; ++b) {
    for (int f = 1; f <= 3; ++f) {
      for (int c = 1; c <= 3; ++c) {
        const std::uint16_t index = LogicConditionIndex(b, f, c);
        Check(od, index, 2, number_rule(index, 1));
        Check(od, index, 4, number_rule(index, 3));
      }
    }
  }
}

void ValveRules::InstallLookupTableRules(int table) {
  ObjectDictionary& od = od_;
  ObjectDictionary* dict = &od_;
  const std::uint16_t type_index = LutIndex(table, 5);
  const std::uint16_t x_index = LutIndex(table, 6);
  for (int k = 1; k <= kLutPoints; ++k) {
    const auto sub = static_cast<std::uint8_t>(k);
    Check(od, x_index, sub, [dict, type_index, x_index, k](std::int64_t v) {
      const auto x = static_cast<double>(v);
      if (Value(*dict, type_index, 1) == 1) {
        // §1.7.4: point 1 is (0 ms, 0); the others 1 ms .. 24 h.
        if (k == 1) return Within(x, 0, 0);
        return Within(x, 1, 86'400'000);
      }
      // §1.7.1 / §3.4.68: MinInt16 <= X1 <= X2 <= ... <= X11 <= MaxInt16.
      const double low =
          k > 1 ? static_cast<double>(Value(*dict, x_index, static_cast<std::uint8_t>(k - 1))) : -32768;
      const double high = k < kLutPoints
                              ? static_cast<double>(Value(*dict, x_index, static_cast<std::uint8_t>(k + 1)))
                              : 32767;
      return Within(x, std::max(low, -32768.0), std::min(high, 32767.0));
    });
  }
  OnWrite(od, type_index, 1, [this, table] {
    if (Value(od_, LutIndex(table, 5), 1) != 1) return;
    OdRef(od_, LutIndex(table, 3), 0).Set(0);  // "3yz3h ... is automatically set to 0"
    OdRef(od_, LutIndex(table, 6), 1).Set(0);  // "sub-index 1 which is automatically set to [0,0]"
    OdRef(od_, LutIndex(table, 7), 1).Set(0);
  });
}

void ValveRules::InstallMiscRules() {
  ObjectDictionary& od = od_;
  ObjectDictionary* dict = &od_;
  for (int k = 0; k < 12; ++k) {
    const std::uint8_t sub = SubOf(k);
    // §3.4.60/3.4.61: 2520h must always be smaller than 2522h.
    Check(od, kExtraScaling1, sub, [dict, sub](std::int64_t v) {
      return v >= Value(*dict, kExtraScaling2, sub) ? SdoAbort::kValueTooHigh : SdoAbort::kNone;
    });
    Check(od, kExtraScaling2, sub, [dict, sub](std::int64_t v) {
      return v <= Value(*dict, kExtraScaling1, sub) ? SdoAbort::kValueTooLow : SdoAbort::kNone;
    });
  }
  // §3.4.101/3.4.102: 0 V .. 5023h, 5022h .. 36 V (the fixed ends are EDS limits).
  Check(od, kSupplyUnder, 0, [dict](std::int64_t v) {
    return v > Value(*dict, kSupplyOver, 0) ? SdoAbort::kValueTooHigh : SdoAbort::kNone;
  });
  Check(od, kSupplyOver, 0, [dict](std::int64_t v) {
    return v < Value(*dict, kSupplyUnder, 0) ? SdoAbort::kValueTooLow : SdoAbort::kNone;
  });
}

}  // namespace canfleet::devices::valve
