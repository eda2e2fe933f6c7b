#pragma once
/// @file How the Quad encodes communication errors (AX020506 §4.1, §4.2): a lost heartbeat or
/// life guard is EMCY 8130h with description 08h and the silent node's ID as channel, so 1003h
/// reads 0x08nn8130; 1029h sub 1 decides the NMT reaction; 1001h uses bit 0 only (§3.1.3).
/// Errors the manual does not list (bus-off, RPDO timeout/length, SYNC length) keep the CiA 301
/// codes of the default policy, with the same 1001h rule. A monitored node's boot-up is not a
/// Quad error (§4.1 lists none): it is not recorded.

#include <optional>

#include "node/canopen/stack/error_policy.hpp"

namespace canfleet::devices::quad {

class QuadErrorPolicy final : public canopen::ErrorPolicy {
 public:
  std::optional<canopen::CommErrorEncoding> Encode(const canopen::CommError& error) const override;
};

}  // namespace canfleet::devices::quad
