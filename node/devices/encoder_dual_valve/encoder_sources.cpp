#include "node/devices/encoder_dual_valve/encoder_sources.hpp"

#include <optional>
#include <vector>

#include "node/devices/encoder_dual_valve/function_blocks.hpp"
#include "node/devices/encoder_dual_valve/pulse_inputs.hpp"
#include "node/devices/encoder_dual_valve/valve_outputs.hpp"
#include "node/devices/od_ref.hpp"

namespace canfleet::devices::encoder {

using blocks::Signal;
using blocks::SourceKind;

namespace {

std::optional<double> NumberAt(canopen::ObjectDictionary& od, std::uint16_t index, std::uint8_t sub) {
  if (!od.Find(index, sub)) return std::nullopt;
  return OdRef(od, index, sub).GetNumber();
}

}  // namespace

std::span<const blocks::SourceType> EncoderValveSourceTypes() {
  static const std::vector<blocks::SourceType> table = [] {
    const auto base = blocks::EncoderSourceTypes();
    std::vector<blocks::SourceType> t(base.begin(), base.end());
    for (blocks::SourceType& row : t) {
      if (row.kind == SourceKind::kCanMessage) row.last_number = 8;
      if (row.kind == SourceKind::kLookupTable) row.last_number = kLookupTables;
      if (row.kind == SourceKind::kConstant) row.last_number = 12;
    }
    return t;
  }();
  return table;
}

EncoderSources::EncoderSources(canopen::ObjectDictionary& od)
    : od_(od), sources_(EncoderValveSourceTypes(), [this](SourceKind kind, std::uint8_t number) {
        return Resolve(kind, number);
      }) {}

void EncoderSources::SetProviders(const PulseInputs* inputs, const ValveOutputs* outputs,
                                  const FunctionBlocks* blocks) {
  inputs_ = inputs;
  outputs_ = outputs;
  blocks_ = blocks;
}

void EncoderSources::SetRpdoTimeout(std::uint8_t number, bool active) {
  if (number >= 1 && number <= rpdo_timeout_.size()) rpdo_timeout_.set(number - 1u, active);
}

bool EncoderSources::TimedOut(std::uint16_t index, std::uint8_t sub) const {
  for (std::size_t r = 0; r < rpdo_timeout_.size(); ++r) {
    if (!rpdo_timeout_.test(r)) continue;
    const auto mapping = static_cast<std::uint16_t>(0x1600 + r);
    const auto count = od_.GetUnsigned(mapping, 0);
    for (std::uint8_t k = 1; k <= count && k <= 8; ++k) {
      const auto entry = od_.GetUnsigned(mapping, k);
      if ((entry >> 16) == index && ((entry >> 8) & 0xFF) == sub) return true;
    }
  }
  return false;
}

Signal EncoderSources::Received(std::uint8_t number) const {
  Signal s;
  std::uint16_t index = kAoProcessValue;
  std::uint8_t sub = number;
  if (number <= kOutputs) {
    s.min = static_cast<double>(od_.GetSigned(kAoScaling1Pv, sub));
    s.max = static_cast<double>(od_.GetSigned(kAoScaling2Pv, sub));
    s.decimal_digits = static_cast<std::uint8_t>(od_.GetUnsigned(kAoPvDigits, sub));
  } else {
    index = kEcValue;
    sub = static_cast<std::uint8_t>(number - kOutputs);
    s.min = static_cast<double>(od_.GetSigned(kEcScaling1, sub));
    s.max = static_cast<double>(od_.GetSigned(kEcScaling2, sub));
    s.decimal_digits = static_cast<std::uint8_t>(od_.GetUnsigned(kEcDigits, sub));
  }
  s.value = static_cast<double>(od_.GetSigned(index, sub));
  s.error = TimedOut(index, sub);
  return s;
}

Signal EncoderSources::Resolve(SourceKind kind, std::uint8_t number) const {
  const int n = number - 1;
  switch (kind) {
    case SourceKind::kCanMessage:
      return Received(number);
    case SourceKind::kAnalogInput:
      return inputs_ && n >= 0 && n < kInputs ? inputs_->AsSource(n) : Signal::NotAvailable();
    case SourceKind::kOutputCommand:
      return outputs_ && n >= 0 && n < kOutputs ? outputs_->Target(n) : Signal::NotAvailable();
    case SourceKind::kOutputFeedback:
      return outputs_ && n >= 0 && n < kOutputs ? outputs_->Feedback(n) : Signal::NotAvailable();
    case SourceKind::kLookupTable:
      return blocks_ && n >= 0 && n < kLookupTables ? blocks_->Lut(n) : Signal::NotAvailable();
    case SourceKind::kMath:
      return blocks_ && n >= 0 && n < kMathBlocks ? blocks_->Math(n) : Signal::NotAvailable();
    case SourceKind::kPid:
      return blocks_ ? blocks_->Pid() : Signal::NotAvailable();
    case SourceKind::kConstant: {
      const auto c = NumberAt(od_, kConstants, number);
      return c ? Signal::Constant(*c) : Signal::NotAvailable();
    }
    case SourceKind::kSupplyVoltage:
    case SourceKind::kProcessorTemperature: {
      const bool supply = kind == SourceKind::kSupplyVoltage;
      const auto v = NumberAt(od_, supply ? kSupplyVoltage : kCpuTemperature, 0);
      if (!v) return Signal::NotAvailable();
      Signal s;
      s.value = *v;
      s.min = supply ? 0.0 : -40.0;
      s.max = supply ? 60.0 : 125.0;
      return s;
    }
    default:
      return Signal::NotAvailable();  // logic, set/reset, DTC: no objects (README-dictionary 44)
  }
}

bool EncoderSources::PairIs(std::uint16_t source_index, std::uint8_t source_sub, std::uint16_t number_index,
                            std::uint8_t number_sub, SourceKind kind, std::uint8_t number) const {
  const auto code = static_cast<std::uint8_t>(od_.GetUnsigned(source_index, source_sub));
  return sources_.KindOf(code) == kind && od_.GetUnsigned(number_index, number_sub) == number;
}

bool EncoderSources::Wired(SourceKind kind, std::uint8_t number) const {
  for (std::uint8_t o = 1; o <= kOutputs; ++o) {
    if (PairIs(kAoControlSource, o, kAoControlNumber, o, kind, number) ||
        PairIs(kAoEnableSource, o, kAoEnableNumber, o, kind, number) ||
        PairIs(kAoOverrideSource, o, kAoOverrideNumber, o, kind, number))
      return true;
  }
  for (int t = 1; t <= kLookupTables; ++t) {
    if (PairIs(LutIndex(t, kLutSource), 0, LutIndex(t, kLutNumber), 0, kind, number)) return true;
  }
  for (int m = 1; m <= kMathBlocks; ++m) {
    if (od_.GetUnsigned(kMathEnable, static_cast<std::uint8_t>(m)) == 0) continue;
    for (std::uint8_t i = 1; i <= kMathInputs; ++i) {
      if (PairIs(MathIndex(m, kMathSource), i, MathIndex(m, kMathNumber), i, kind, number)) return true;
    }
  }
  return PairIs(kPidTargetSource, 0, kPidTargetNumber, 0, kind, number) ||
         PairIs(kPidFeedbackSource, 0, kPidFeedbackNumber, 0, kind, number);
}

}  // namespace canfleet::devices::encoder
