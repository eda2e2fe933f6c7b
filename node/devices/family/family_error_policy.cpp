#include "node/devices/family/family_error_policy.hpp"

namespace canfleet::devices::family {

using canopen::CommErrorKind;

canopen::ErrorEntry MakeFamilyEntry(std::uint16_t code, std::uint8_t description, std::uint8_t channel) {
  canopen::ErrorEntry e;
  e.code = code;
  e.info = static_cast<std::uint16_t>((description << 8) | channel);
  e.register_bits = canopen::kErrorRegisterGeneric;
  e.msef = {channel, description, 0, 0, 0};
  return e;
}

std::optional<canopen::CommErrorEncoding> FamilyErrorPolicy::Encode(const canopen::CommError& error) const {
  const ErrorConventions& c = conventions_;
  auto encoded = [&](std::uint16_t code, std::uint8_t description, std::uint8_t channel) {
    return canopen::CommErrorEncoding{MakeFamilyEntry(code, description, channel),
                                      c.communication_behaviour_sub};
  };
  switch (error.kind) {
    case CommErrorKind::kHeartbeatTimeout:
      return encoded(c.heartbeat_code, c.heartbeat_description, static_cast<std::uint8_t>(error.detail));
    case CommErrorKind::kLifeGuardTimeout:
      return encoded(c.life_guard_code, c.life_guard_description, 0);
    case CommErrorKind::kRpdoTimeout:
      return encoded(c.rpdo_timeout_code, c.rpdo_timeout_description, 0);
    case CommErrorKind::kBusOff:
      return encoded(c.bus_off_code, c.bus_off_description, 0);
    case CommErrorKind::kBootUpOfMonitored:
      return std::nullopt;  // a watched node that boots again is no error in any of the tables
    default:
      break;
  }
  // What the manuals do not list (error passive, PDO length, SYNC length...): CiA 301's code, with
  // only the generic bit of 1001h, as every table of the family says.
  auto encoding = ErrorPolicy::Encode(error);
  if (encoding) encoding->entry.register_bits = canopen::kErrorRegisterGeneric;
  return encoding;
}

void ApplyConventions(const ErrorConventions& conventions, canopen::StackOptions& options) {
  options.emcy.max_history = conventions.history_depth;
  options.emcy.remove_cleared_from_history = true;
}

}  // namespace canfleet::devices::family
