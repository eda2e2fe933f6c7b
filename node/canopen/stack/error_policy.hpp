#pragma once
/// @file Turns communication errors reported by services into what the network sees: an EMCY
/// code, a 1003h entry, 1001h bits and the 1029h error-behaviour sub-index that decides the NMT
/// reaction. The default follows CiA 301; a device whose manual encodes errors differently
/// (e.g. the Quad controller's 0x08nn8130 for a lost heartbeat) supplies its own policy.

#include <cstdint>
#include <optional>

#include "node/canopen/common/comm_error.hpp"
#include "node/canopen/emcy/error_entry.hpp"

namespace canfleet::canopen {

struct CommErrorEncoding {
  ErrorEntry entry;
  /// 1029h sub-index whose value decides the NMT reaction (0 = no reaction).
  std::uint8_t behaviour_sub = 1;
};

class ErrorPolicy {
 public:
  virtual ~ErrorPolicy() = default;
  /// nullopt: the error is not recorded at all.
  virtual std::optional<CommErrorEncoding> Encode(const CommError& error) const;
};

/// 1001h bit 4: communication error (CiA 301 §7.5.2.2).
inline constexpr std::uint8_t kErrorRegisterCommunication = 0x10;

}  // namespace canfleet::canopen
