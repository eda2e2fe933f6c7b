#pragma once
/// @file The heartbeat objects of CiA 301 v4.2: 1016h consumer heartbeat time (§7.5.2.19) and
/// 1017h producer heartbeat time (§7.5.2.20).

#include <cstdint>

#include "node/canopen/od/object_dictionary.hpp"

namespace canfleet::canopen {

inline constexpr std::uint16_t kConsumerHeartbeatTimeIndex = 0x1016;
inline constexpr std::uint16_t kProducerHeartbeatTimeIndex = 0x1017;

/// Adds 1017h producer heartbeat time (U16 ms, rw, default 0) and, if `consumer_entries` > 0,
/// 1016h consumer heartbeat time (ARRAY: sub0 U8 ro = number of entries, sub1..n U32 rw,
/// default 0 = unused). `consumer_entries` is capped at 127.
void AddHeartbeatObjects(ObjectDictionary& od, std::uint8_t consumer_entries);

}  // namespace canfleet::canopen
