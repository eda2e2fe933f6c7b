#include "node/devices/power_supply_24v_350w/ps_validators.hpp"

#include <algorithm>
#include <vector>

#include "node/devices/od_ref.hpp"
#include "node/devices/power_supply_24v_350w/ps_objects.hpp"

namespace canfleet::devices::ps {

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

}  // namespace

void InstallPsValidators(canopen::CanopenStack& stack) {
  ObjectDictionary& od = stack.od();
  canopen::CanopenStack* node = &stack;

  // §2.2.13: only while no error is present ("1001h = 1" in the note is read as "1001h = 0").
  for (std::uint8_t sub = 1; sub <= 4; ++sub) {
    if (!od.Find(0x1029, sub)) continue;
    Entry(od, 0x1029, sub)
        .AddValidator([node](const SubObject&, std::span<const std::uint8_t>, Origin origin) {
          return origin != Origin::kDevice && node->emcy().ErrorRegister() != 0 ? SdoAbort::kDeviceState
                                                                                : SdoAbort::kNone;
        });
  }

  const std::vector<std::int64_t> off_on_none = {kCommandOff, kCommandOn, kNoAction};
  const std::vector<std::int64_t> quit_none = {kQuitFailure, kNoAction};
  AllowOnly(Entry(od, kGeneralCommands, 1), {kControlLocal, kControlRemote, kControlBoth});
  AllowOnly(Entry(od, kGeneralCommands, 2), quit_none);
  AllowOnly(Entry(od, kGeneralCommands, 4), off_on_none);
  AllowOnly(Entry(od, kOutputCommands, 2), off_on_none);
  AllowOnly(Entry(od, kOutputCommands, 3), quit_none);
  AllowOnly(Entry(od, kOutputCommands, 5), off_on_none);

  ObjectDictionary* dict = &od;
  for (std::uint8_t n = 1; n <= 10; ++n) {
    Entry(od, kScaling1, n)
        .AddValidator([dict, n](const SubObject& s, std::span<const std::uint8_t> data, Origin) {
          return Decode(s, data) >= dict->GetSigned(kScaling2, n) ? SdoAbort::kValueTooHigh : SdoAbort::kNone;
        });
    Entry(od, kScaling2, n)
        .AddValidator([dict, n](const SubObject& s, std::span<const std::uint8_t> data, Origin) {
          return Decode(s, data) <= dict->GetSigned(kScaling1, n) ? SdoAbort::kValueTooLow : SdoAbort::kNone;
        });
  }

  AllowOnly(Entry(od, kChangeBaudRate, 0), {0, 1, 2, 3, 4, 6, 7, 8});
  Entry(od, kChangeNodeId, 0)
      .AddValidator([](const SubObject& s, std::span<const std::uint8_t> data, Origin) {
        const auto id = Decode(s, data);
        if (id < 1) return SdoAbort::kValueTooLow;
        if (id > 127) return SdoAbort::kValueTooHigh;
        return SdoAbort::kNone;
      });
}

}  // namespace canfleet::devices::ps
