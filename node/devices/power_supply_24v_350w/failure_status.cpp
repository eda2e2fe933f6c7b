#include "node/devices/power_supply_24v_350w/failure_status.hpp"

#include <algorithm>
#include <chrono>

#include "node/devices/power_supply_24v_350w/ps_objects.hpp"

namespace canfleet::devices::ps {

FailureStatus::FailureStatus(canopen::ObjectDictionary& od, std::uint16_t index)
    : condition_(od, index, kCondition),
      logic_(od, index, kLogic),
      event_(od, index, kEvent),
      fault_state_(od, index, kFaultState),
      indication_(od, index, kIndication) {}

void FailureStatus::AddFlag(unsigned shift, OdRef threshold, OdRef return_value, OdRef delay) {
  Flag flag;
  flag.shift = shift;
  flag.threshold = threshold;
  flag.return_value = return_value;
  flag.delay = delay;
  flags_.push_back(flag);
}

std::uint32_t FailureStatus::DefaultBits(const OdRef& ref, unsigned shift) {
  return static_cast<std::uint32_t>(canopen::DecodeUnsignedLe(ref.sub().default_value) >> shift) & 0b11u;
}

std::uint32_t FailureStatus::With(std::uint32_t word, unsigned shift, std::uint32_t bits) {
  return (word & ~(0b11u << shift)) | ((bits & 0b11u) << shift);
}

bool FailureStatus::Update(std::span<const std::int64_t> values, TimePoint now) {
  auto condition = static_cast<std::uint32_t>(condition_.Get());
  auto event = static_cast<std::uint32_t>(event_.Get());
  auto indication = static_cast<std::uint32_t>(indication_.Get());
  const auto logic = static_cast<std::uint32_t>(logic_.Get());
  const auto fault_state = static_cast<std::uint32_t>(fault_state_.Get());
  for (std::size_t i = 0; i < flags_.size() && i < values.size(); ++i) {
    Flag& f = flags_[i];
    const std::int64_t value = values[i];
    const std::int64_t threshold = f.threshold ? f.threshold.Get() : 1;
    const std::int64_t back = f.return_value ? f.return_value.Get() : 1;
    // §2.3.9: 01 "higher or equal than threshold", 00 "lower than return"; in between (a
    // hysteresis band, §1.2.3) the previous state holds; a flag never measured (1x) starts low.
    std::uint32_t state = (condition >> f.shift) & 0b11u;
    if (value >= threshold)
      state = kFlagHigh;
    else if (value < back)
      state = kFlagLow;
    else if (state > kFlagHigh)
      state = kFlagLow;
    condition = With(condition, f.shift, state);

    const std::uint32_t flag_logic = (logic >> f.shift) & 0b11u;
    const bool configured = flag_logic == kFlagLow || flag_logic == kFlagHigh;
    const bool match = configured && state == flag_logic;
    if (!match) {
      f.since.reset();
    } else if (!f.since) {
      f.since = now;
      f.pending_delay = std::chrono::milliseconds(std::max<std::int64_t>(0, f.delay.Get()));
    }
    const bool on = match && now - *f.since >= f.pending_delay;
    f.indication = on && ((fault_state >> f.shift) & 0b11u) == kFlagProcess;
    if (configured) {
      event = With(event, f.shift, on ? kFlagOn : kFlagOff);
      indication = With(indication, f.shift, f.indication ? kFlagOn : kFlagOff);
    } else {
      event = With(event, f.shift, DefaultBits(event_, f.shift));
      indication = With(indication, f.shift, DefaultBits(indication_, f.shift));
    }
  }
  bool changed = condition_.Set(condition);
  changed = event_.Set(event) || changed;
  changed = indication_.Set(indication) || changed;
  return changed;
}

bool FailureStatus::AnyIndication() const {
  return std::any_of(flags_.begin(), flags_.end(), [](const Flag& f) { return f.indication; });
}

bool FailureStatus::Indication(unsigned shift) const {
  for (const Flag& f : flags_) {
    if (f.shift == shift) return f.indication;
  }
  return false;
}

bool FailureStatus::Pending() const {
  const auto event = static_cast<std::uint32_t>(event_.Get());
  return std::any_of(flags_.begin(), flags_.end(),
                     [event](const Flag& f) { return f.since && ((event >> f.shift) & 0b11u) != kFlagOn; });
}

void FailureStatus::Reset() {
  for (Flag& f : flags_) {
    f.since.reset();
    f.indication = false;
  }
}

}  // namespace canfleet::devices::ps
