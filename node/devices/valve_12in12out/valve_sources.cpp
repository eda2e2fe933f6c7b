#include "node/devices/valve_12in12out/valve_sources.hpp"

#include <algorithm>
#include <cmath>

#include "node/devices/valve_12in12out/input_block.hpp"
#include "node/devices/valve_12in12out/program_blocks.hpp"

namespace canfleet::devices::valve {

using blocks::Signal;
using blocks::SourceKind;

bool IsOn(const Signal& s) {
  if (!s.available) return false;
  if (!s.has_range || s.min == s.max) return s.value != 0.0;
  const double middle = (s.min + s.max) / 2.0;
  return s.min < s.max ? s.value >= middle : s.value <= middle;
}

ValveSources::ValveSources(canopen::ObjectDictionary& od)
    : od_(od), sources_(blocks::ValveSourceTypes(), [this](SourceKind kind, std::uint8_t number) {
        return Resolve(kind, number);
      }) {
  for (int ch = 0; ch < kOutputs; ++ch) {
    const std::uint8_t sub = SubOf(ch);
    pv_[ch] = OdRef(od, kAoProcessValue, sub);
    scaling1_[ch] = OdRef(od, kAoScaling1Pv, sub);
    scaling2_[ch] = OdRef(od, kAoScaling2Pv, sub);
    pv_digits_[ch] = OdRef(od, kAoPvDigits, sub);
    type_[ch] = OdRef(od, kAoType, sub);
    commanded_[ch] = OdRef(od, kAoFieldValue, sub);
    feedback_[ch] = OdRef(od, kAoFeedback, sub);
  }
  write_state_ = {OdRef(od, kDoWriteState, 1), OdRef(od, kDoWriteState, 2)};
  for (int k = 0; k < 12; ++k) {
    const std::uint8_t sub = SubOf(k);
    extra_[k] = OdRef(od, kExtraPv, sub);
    extra_scaling1_[k] = OdRef(od, kExtraScaling1, sub);
    extra_scaling2_[k] = OdRef(od, kExtraScaling2, sub);
    extra_digits_[k] = OdRef(od, kExtraDigits, sub);
  }
  for (int k = 0; k < 15; ++k)
    constants_[k] = OdRef(od, kConstant, SubOf(k));
  supply_ = OdRef(od, kSupplyVoltage, 0);
  temperature_ = OdRef(od, kTemperature, 0);
}

void ValveSources::SetRpdoTimeout(std::size_t rpdo, bool active) {
  std::erase_if(timed_out_, [rpdo](const auto& entry) { return entry.first == rpdo; });
  if (!active || rpdo == 0) return;
  std::vector<std::pair<std::uint16_t, std::uint8_t>> mapped;
  const auto map_index = static_cast<std::uint16_t>(0x1600 + rpdo - 1);
  const auto count = od_.GetUnsigned(map_index, 0);
  for (std::uint8_t k = 1; k <= count && k <= 64; ++k) {
    const auto entry = static_cast<std::uint32_t>(od_.GetUnsigned(map_index, k));
    mapped.emplace_back(static_cast<std::uint16_t>(entry >> 16), static_cast<std::uint8_t>(entry >> 8));
  }
  timed_out_.emplace_back(rpdo, std::move(mapped));
}

bool ValveSources::TimedOut(std::uint16_t index, std::uint8_t sub) const {
  for (const auto& [rpdo, mapped] : timed_out_) {
    for (const auto& [i, s] : mapped) {
      if (i == index && s == sub) return true;
    }
  }
  return false;
}

Signal ValveSources::OutputValue(const OdRef& value, int ch) const {
  Signal s;
  s.value = static_cast<double>(value.Get());
  s.min = static_cast<double>(scaling1_[ch].Get());
  s.max = static_cast<double>(scaling2_[ch].Get());
  s.decimal_digits = static_cast<std::uint8_t>(std::clamp<std::int64_t>(pv_digits_[ch].Get(), 0, 4));
  return s;
}

Signal ValveSources::CanMessage(std::uint8_t number) const {
  if (number >= 1 && number <= kOutputs) {
    const int ch = number - 1;
    const bool proportional = ch < kProportionalOutputs;
    if (proportional && !IsDigitalType(type_[ch].Get())) {
      Signal s = OutputValue(pv_[ch], ch);
      s.error = TimedOut(kAoProcessValue, SubOf(ch));
      return s;
    }
    // Table 16 "*": a digital output reads its bit of 6200h (sub 1 = OUT1-8, sub 2 = DO1-DO4).
    const int line = proportional ? 0 : 1;
    const int bit = proportional ? ch : ch - kProportionalOutputs;
    Signal s = OutputValue(write_state_[line], ch);
    s.value = write_state_[line].Bit(static_cast<unsigned>(bit)) ? 1.0 : 0.0;
    s.error = TimedOut(kDoWriteState, static_cast<std::uint8_t>(line + 1));
    return s;
  }
  if (number >= 13 && number <= 24) {
    const int k = number - 13;
    Signal s;
    s.value = static_cast<double>(extra_[k].Get());
    s.min = static_cast<double>(extra_scaling1_[k].Get());
    s.max = static_cast<double>(extra_scaling2_[k].Get());
    s.decimal_digits = static_cast<std::uint8_t>(std::clamp<std::int64_t>(extra_digits_[k].Get(), 0, 4));
    s.error = TimedOut(kExtraPv, SubOf(k));
    return s;
  }
  return Signal::NotAvailable();
}

Signal ValveSources::Resolve(SourceKind kind, std::uint8_t number) const {
  switch (kind) {
    case SourceKind::kCanMessage:
      return CanMessage(number);
    case SourceKind::kAnalogInput:
      if (!inputs_ || number < 1 || number > kInputs) return Signal::NotAvailable();
      return inputs_->AsSource(number - 1);
    case SourceKind::kConstant:
      if (number < 1 || number > 15) return Signal::NotAvailable();
      return Signal::Constant(constants_[number - 1].GetNumber());
    case SourceKind::kPid:
      if (!program_ || number < 1 || number > kPids) return Signal::NotAvailable();
      return program_->PidOutput(number - 1);
    case SourceKind::kLookupTable:
      if (!program_ || number < 1 || number > kLookupTables) return Signal::NotAvailable();
      return program_->LutOutput(number - 1);
    case SourceKind::kMath:
      if (!program_ || number < 1 || number > kMathBlocks) return Signal::NotAvailable();
      return program_->MathOutput(number - 1);
    case SourceKind::kLogic:
      if (!program_ || number < 1 || number > kLogicBlocks) return Signal::NotAvailable();
      return program_->LogicOutput(number - 1);
    case SourceKind::kOutputCommand:
      if (number < 1 || number > kOutputs) return Signal::NotAvailable();
      return OutputValue(commanded_[number - 1], number - 1);
    case SourceKind::kOutputFeedback:
      if (number < 1 || number > kOutputs) return Signal::NotAvailable();
      return OutputValue(feedback_[number - 1], number - 1);
    case SourceKind::kSupplyVoltage: {
      Signal s = Signal::Constant(std::round(supply_.GetNumber() * 10.0));  // Table 17: 1 digit
      s.decimal_digits = 1;
      return s;
    }
    case SourceKind::kProcessorTemperature: {
      Signal s = Signal::Constant(std::round(temperature_.GetNumber() * 10.0));
      s.decimal_digits = 1;
      return s;
    }
    default:
      return Signal::NotAvailable();
  }
}

}  // namespace canfleet::devices::valve
