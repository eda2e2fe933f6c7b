#include "node/devices/encoder_dual_valve/supply_monitor.hpp"

#include <algorithm>
#include <cmath>

#include "node/devices/family/family_error_policy.hpp"

namespace canfleet::devices::encoder {

SupplyMonitor::SupplyMonitor(canopen::CanopenStack& stack, Scheduler& scheduler, EncoderIo& io) : io_(io) {
  auto& od = stack.od();
  supply_ = OdRef(od, kSupplyVoltage, 0);
  temperature_ = OdRef(od, kCpuTemperature, 0);
  enable_ = OdRef(od, kFdEnable, 0);
  for (std::uint8_t i = 0; i < 3; ++i) {
    field_[i] = OdRef(od, kFdFieldValue, static_cast<std::uint8_t>(i + 1));
    set_[i] = OdRef(od, kFdSetThreshold, static_cast<std::uint8_t>(i + 1));
    clear_[i] = OdRef(od, kFdClearThreshold, static_cast<std::uint8_t>(i + 1));
    delay_[i] = OdRef(od, kFdDelay, static_cast<std::uint8_t>(i + 1));
  }
  const auto fault = [&](std::uint16_t code, std::uint8_t description) {
    return std::make_unique<DelayedFault>(scheduler, stack, family::MakeFamilyEntry(code, description, 0),
                                          kBehaviourOther);
  };
  watches_[kTemperature].fault = fault(kEmcyTemperature, kDescHigh);
  watches_[kOverVoltage].fault = fault(kEmcyVoltage, kDescHigh);
  watches_[kUnderVoltage].fault = fault(kEmcyVoltage, kDescLow);
}

void SupplyMonitor::Step(State& s, bool enabled, bool set, bool clear, Ms delay, Ms elapsed) {
  s.delay = delay;
  if (!enabled) {
    s.flag = false;
    s.held = Ms{0};
    s.active = false;
  } else if (!s.flag) {
    if (set) {
      s.flag = true;  // counts from this evaluation on
      s.held = Ms{0};
    }
  } else if (clear) {
    s.flag = false;
    s.held = Ms{0};
    s.active = false;
  } else {
    s.held += elapsed;
  }
  if (s.flag && s.held >= s.delay) s.active = true;
  s.fault->Update(s.active, Duration::zero());
}

void SupplyMonitor::Update(Ms elapsed) {
  supply_V_ = io_.supply->Number() / 1000.0;  // 5020h counts V
  const double celsius = io_.temperature->Number();
  supply_.SetNumber(supply_V_);
  temperature_.SetNumber(celsius);
  const double t10 = std::round(celsius * 10.0);
  const double v10 = std::round(supply_V_ * 10.0);
  field_[0].SetNumber(t10);
  field_[1].SetNumber(v10);
  field_[2].SetNumber(v10);
  const auto threshold = [](const OdRef& r) { return static_cast<double>(r.Get()); };
  const auto delay = [&](std::size_t i) { return Ms{100 * std::max<std::int64_t>(0, delay_[i].Get())}; };
  const bool supply_on = enable_.Bit(0);
  const bool temperature_on = enable_.Bit(1);
  Step(watches_[kTemperature], temperature_on, t10 >= threshold(set_[0]), t10 <= threshold(clear_[0]),
       delay(0), elapsed);
  Step(watches_[kOverVoltage], supply_on, v10 >= threshold(set_[1]), v10 <= threshold(clear_[1]), delay(1),
       elapsed);
  Step(watches_[kUnderVoltage], supply_on, v10 <= threshold(set_[2]), v10 >= threshold(clear_[2]), delay(2),
       elapsed);
}

bool SupplyMonitor::OutputsOff() const {
  if (supply_V_ < kShutdownVoltage) return true;
  return std::any_of(watches_.begin(), watches_.end(), [](const State& s) { return s.active; });
}

std::optional<SupplyMonitor::Ms> SupplyMonitor::NextChange() const {
  std::optional<Ms> next;
  for (const State& s : watches_) {
    if (!s.flag || s.active) continue;
    const Ms left = std::max(Ms{1}, s.delay - s.held);
    next = next ? std::min(*next, left) : left;
  }
  return next;
}

void SupplyMonitor::Reset() {
  for (State& s : watches_) {
    s.flag = false;
    s.held = Ms{0};
    s.active = false;
    s.fault->Reset();
  }
}

}  // namespace canfleet::devices::encoder
