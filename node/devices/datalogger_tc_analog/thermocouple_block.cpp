#include "node/devices/datalogger_tc_analog/thermocouple_block.hpp"

#include <algorithm>
#include <cmath>

#include "node/devices/datalogger_tc_analog/tc_conversion.hpp"
#include "node/devices/family/family_error_policy.hpp"

namespace canfleet::devices::datalogger {

namespace {

constexpr std::int64_t kOverRange = 32767;  // INTEGER16 full scale: an ADC over-range reading

// Table 26: description per flag.
constexpr std::array<std::uint8_t, ThermocoupleBlock::kLimits> kLimitDescriptions = {
    kDescTcLowWarning, kDescTcHighWarning, kDescTcLowShutdown, kDescTcHighShutdown};
constexpr std::array<std::uint16_t, ThermocoupleBlock::kLimits> kLimitObjects = {
    kTcLowWarning, kTcHighWarning, kTcLowShutdown, kTcHighShutdown};

// Table 26 channel byte of TC n: 10h, 20h, 30h, 40h.
std::uint8_t ChannelId(int ch) {
  return static_cast<std::uint8_t>((ch + 1) << 4);
}

thermocouple::ThermocoupleType TypeOf(const OdRef& type) {
  // A value the validators refused cannot be there; an edited EDS default might: read it as K.
  return TcTypeFromCode(static_cast<std::uint16_t>(type.Get())).value_or(thermocouple::ThermocoupleType::kK);
}

}  // namespace

ThermocoupleBlock::ThermocoupleBlock(canopen::ObjectDictionary& od, const DataLoggerIo& io,
                                     Scheduler& scheduler, std::span<canopen::CanopenStack* const> stacks)
    : io_(io), cj_pv_(od, kTcColdJunctionPv, 0) {
  for (int ch = 0; ch < kThermocouples; ++ch) {
    Channel& c = channels_[static_cast<std::size_t>(ch)];
    const std::uint8_t sub = SubOf(ch);
    c.type = OdRef(od, kSensorType, static_cast<std::uint8_t>(kTcTypeSubOffset + sub));
    c.cj_enabled = OdRef(od, kTcColdJunctionEnabled, sub);
    c.field_value = OdRef(od, kTcFieldValue, sub);
    c.process_value = OdRef(od, kTcProcessValue, sub);
    c.cj_output = OdRef(od, kTcColdJunctionFv, sub);
    c.hysteresis = OdRef(od, kTcHysteresis, sub);
    for (std::size_t l = 0; l < kLimits; ++l) {
      c.thresholds[l] = OdRef(od, kLimitObjects[l], sub);
      c.limit_faults[l] = std::make_unique<DeviceFault>(
          scheduler, stacks, family::MakeFamilyEntry(kEmcyTcLimit, kLimitDescriptions[l], ChannelId(ch)),
          kBehaviourInputFault);
    }
    c.open_fault = std::make_unique<DeviceFault>(
        scheduler, stacks, family::MakeFamilyEntry(kEmcyTcOverload, kDescTcOpen, ChannelId(ch)),
        kBehaviourInputFault);
  }
}

void ThermocoupleBlock::Convert() {
  const double cold = io_.cold_junction->Number();
  cj_pv_.SetNumber(cold * 10.0);
  for (int ch = 0; ch < kThermocouples; ++ch) {
    Channel& c = channels_[static_cast<std::size_t>(ch)];
    const auto type = TypeOf(c.type);
    const TcReading r = ConvertThermocouple(type, io_.tc_temperature[static_cast<std::size_t>(ch)]->Number(),
                                            cold, c.cj_enabled.Get() != 0);
    c.cj_output.SetNumber(r.cold_junction_mv * 1000.0);  // saturates at the INTEGER16 ends
    c.open = io_.tc_open[static_cast<std::size_t>(ch)]->Bool();
    if (c.open) {
      c.process_value.Set(kOverRange);
      c.field_value.Set(kOverRange);
    } else {
      c.process_value.SetNumber(r.measured_mv * 1000.0);
      c.field_value.SetNumber(r.temperature_c * 10.0);
    }
  }
}

void ThermocoupleBlock::EvaluateFaults() {
  for (Channel& c : channels_) {
    if (c.open) {
      c.flags.fill(false);
    } else {
      const std::int64_t fv = c.field_value.Get();
      const std::int64_t hysteresis = std::max<std::int64_t>(0, c.hysteresis.Get());
      for (std::size_t l = 0; l < kLimits; ++l) {
        const std::int64_t limit = c.thresholds[l].Get();
        const bool low = l == kLowWarning || l == kLowShutdown;
        bool& flag = c.flags[l];
        if (low) {
          if (fv < limit)
            flag = true;
          else if (flag && fv >= limit + hysteresis)
            flag = false;
        } else {
          if (fv > limit)
            flag = true;
          else if (flag && fv <= limit - hysteresis)
            flag = false;
        }
      }
    }
    for (std::size_t l = 0; l < kLimits; ++l)
      c.limit_faults[l]->Set(c.flags[l]);
    c.open_fault->Set(c.open);
  }
}

blocks::Signal ThermocoupleBlock::TemperatureSource(int ch) const {
  const Channel& c = channels_.at(static_cast<std::size_t>(ch));
  blocks::Signal s;
  s.value = static_cast<double>(c.field_value.Get());
  s.min = static_cast<double>(c.thresholds[kLowWarning].Get());
  s.max = static_cast<double>(c.thresholds[kHighWarning].Get());
  s.decimal_digits = 1;
  s.error = c.open;
  return s;
}

blocks::Signal ThermocoupleBlock::ColdJunctionSource(int ch) const {
  const Channel& c = channels_.at(static_cast<std::size_t>(ch));
  const auto type = TypeOf(c.type);
  blocks::Signal s;
  s.value = static_cast<double>(c.cj_output.Get());
  s.min = std::round(EmfClamped(type, -40.0) * 1000.0);
  s.max = std::round(EmfClamped(type, 210.0) * 1000.0);
  s.decimal_digits = 3;
  return s;
}

void ThermocoupleBlock::Reset() {
  for (Channel& c : channels_) {
    c.flags.fill(false);
    c.open = false;
  }
}

void ThermocoupleBlock::ResetPort(std::size_t port) {
  for (Channel& c : channels_) {
    for (auto& fault : c.limit_faults)
      fault->ResetPort(port);
    c.open_fault->ResetPort(port);
  }
}

}  // namespace canfleet::devices::datalogger
