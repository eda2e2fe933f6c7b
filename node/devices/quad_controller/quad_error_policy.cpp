#include "node/devices/quad_controller/quad_error_policy.hpp"

#include "node/devices/quad_controller/quad_objects.hpp"

namespace canfleet::devices::quad {

using canopen::CommErrorKind;

canopen::ErrorEntry MakeErrorEntry(std::uint16_t code, std::uint8_t description, std::uint8_t channel) {
  canopen::ErrorEntry e;
  e.code = code;
  e.info = static_cast<std::uint16_t>((description << 8) | channel);
  e.register_bits = canopen::kErrorRegisterGeneric;
  e.msef = {channel, description, 0, 0, 0};
  return e;
}

std::optional<canopen::CommErrorEncoding> QuadErrorPolicy::Encode(const canopen::CommError& error) const {
  switch (error.kind) {
    case CommErrorKind::kHeartbeatTimeout:
    case CommErrorKind::kLifeGuardTimeout:
      return canopen::CommErrorEncoding{MakeErrorEntry(kEmcyHeartbeat, kDescHeartbeat, error.detail),
                                        kBehaviourCommunication};
    case CommErrorKind::kBootUpOfMonitored:
      return std::nullopt;
    default:
      break;
  }
  auto encoding = ErrorPolicy::Encode(error);
  if (encoding) encoding->entry.register_bits = canopen::kErrorRegisterGeneric;
  return encoding;
}

}  // namespace canfleet::devices::quad
