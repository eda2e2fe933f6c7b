#include "node/devices/quad_controller/quad_validators.hpp"

#include <algorithm>
#include <initializer_list>
#include <vector>

#include "node/devices/od_ref.hpp"
#include "node/devices/quad_controller/quad_objects.hpp"

namespace canfleet::devices::quad {

namespace {

using canopen::NmtState;
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

void AllowOnly(SubObject& sub, std::vector<std::int64_t> allowed) {
  sub.AddValidator(
      [allowed = std::move(allowed)](const SubObject& s, std::span<const std::uint8_t> data, Origin) {
        return std::find(allowed.begin(), allowed.end(), Decode(s, data)) != allowed.end()
                   ? SdoAbort::kNone
                   : SdoAbort::kInvalidValue;
      });
}

/// Accepts [low(), high()] evaluated at write time.
template <typename Low, typename High>
void Between(SubObject& sub, Low low, High high) {
  sub.AddValidator([low, high](const SubObject& s, std::span<const std::uint8_t> data, Origin) {
    const auto v = Decode(s, data);
    if (v < low()) return SdoAbort::kValueTooLow;
    if (v > high()) return SdoAbort::kValueTooHigh;
    return SdoAbort::kNone;
  });
}

}  // namespace

int InputFullScale(const ObjectDictionary& od, int ch) {
  if (ch >= kAnalogInputs) return 10000;
  switch (static_cast<SensorType>(ValueOf(od, kAiSensorType, SubOf(ch)))) {
    case SensorType::kVoltage5V:
      return 5000;
    case SensorType::kVoltage10V:
      return 10000;
    default:
      return 20000;
  }
}

void InstallQuadValidators(canopen::CanopenStack& stack) {
  ObjectDictionary& od = stack.od();
  // Hooks outlive this function: they hold pointers, not references to locals.
  ObjectDictionary* dict = &od;
  canopen::CanopenStack* node = &stack;

  for (int ch = 0; ch < kInputs; ++ch) {
    const std::uint8_t sub = SubOf(ch);
    AllowOnly(Entry(od, kAiSensorType, sub), ch < kAnalogInputs ? std::vector<std::int64_t>{40, 42, 51, 52}
                                                                : std::vector<std::int64_t>{60, 10000});
    AllowOnly(Entry(od, kAiOperatingMode, sub), {0, 1, 10, 20});

    const auto value = [dict, sub](std::uint16_t index) {
      return [dict, index, sub] { return ValueOf(*dict, index, sub); };
    };
    const auto full_scale = [dict, ch] { return static_cast<std::int64_t>(InputFullScale(*dict, ch)); };
    const auto zero = [] { return std::int64_t{0}; };
    Between(Entry(od, kDiLowThreshold, sub), zero, value(kDiHighThreshold));
    Between(Entry(od, kDiHighThreshold, sub), value(kDiLowThreshold), full_scale);
    for (std::size_t k = 0; k < kAiProfileChain.size(); ++k) {
      SubObject& entry = Entry(od, kAiProfileChain[k], sub);
      const bool first = k == 0;
      const bool last = k + 1 == kAiProfileChain.size();
      if (first)
        Between(entry, zero, value(kAiProfileChain[k + 1]));
      else if (last)
        Between(entry, value(kAiProfileChain[k - 1]), full_scale);
      else
        Between(entry, value(kAiProfileChain[k - 1]), value(kAiProfileChain[k + 1]));
    }
  }
  std::vector<std::int64_t> do_sources = {0, 1, 2, 3, 4, 5, 6, 11, 12, 13, 14, 15, 16};
  for (int o = 0; o < kDigitalOutputs; ++o)
    AllowOnly(Entry(od, kDoControlInput, SubOf(o)), do_sources);
  for (int n = 0; n < kPouts; ++n) {
    const std::uint8_t sub = SubOf(n);
    AllowOnly(Entry(od, kAoControlInput, sub), {0, 1, 2, 3, 4, 5, 6});
    AllowOnly(Entry(od, kAoResponse, sub), {0, 1, 2, 3, 4, 5});
    AllowOnly(Entry(od, kAoRampControl, sub), {0, 1, 2});
    AllowOnly(Entry(od, kAoOutputType, sub), {20, 1000});
    Entry(od, kAoFieldValue, sub)
        .AddValidator([dict, sub](const SubObject&, std::span<const std::uint8_t>, Origin) {
          return ValueOf(*dict, kReceivedPvStatus, sub) == 1 ? SdoAbort::kDeviceState : SdoAbort::kNone;
        });
  }

  // §4.2: output control by SDO only in operational (PDOs run only there anyway).
  const auto refuse_in_pre_operational = [node](const SubObject&, std::span<const std::uint8_t>,
                                                Origin origin) {
    return origin == Origin::kSdo && node->State() != NmtState::kOperational ? SdoAbort::kDeviceState
                                                                             : SdoAbort::kNone;
  };
  Entry(od, kDoWriteState, 1).AddValidator(refuse_in_pre_operational);
  for (int n = 0; n < kPouts; ++n) {
    for (std::uint16_t index : {kAoFieldValue, kReceivedPv, kReceivedPvStatus})
      Entry(od, index, SubOf(n)).AddValidator(refuse_in_pre_operational);
  }
}

}  // namespace canfleet::devices::quad
