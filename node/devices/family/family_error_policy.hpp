#pragma once
/// @file The error conventions of the manufacturer's CANopen family (Axiomatic), parametrised per
/// product (framework issue, point 4). The valve (UMAX020411A §3.2.3-3.2.4, Table 33), power supply
/// (UMAX080311 §2.2.2-2.2.4, Table 9), encoder (AX023241, no table: the family's codes) and data
/// logger (UMAX181001 §3.2) manuals encode errors alike:
///
///   1003h entry = description << 24 | channel << 16 | EMCY code   (newest at sub 1)
///   80nn8130h  heartbeat of node nn lost          10008130h  life guard event
///   00008100h  RPDO timeout                        00008140h  bus-off (the tables print 8400h in
///                                                  the EMCY column; 8140h is CiA 301's "recovered
///                                                  from bus off", which the 1003h column gives)
///   1001h      only bit 0 (generic), set while any error is active
///   1003h      at most `history_depth` entries; an error leaves the list when it clears
///
/// The EMCY frame's manufacturer bytes are not described by any of the four manuals; the family's
/// Quad (AX020506 §4.1) puts the channel then the description byte first, and so do we.

#include <cstdint>
#include <optional>

#include "node/canopen/stack/canopen_stack.hpp"
#include "node/canopen/stack/error_policy.hpp"

namespace canfleet::devices::family {

/// What a product's manual says; the defaults are the valve's and power supply's tables.
struct ErrorConventions {
  std::uint8_t heartbeat_description = 0x80;   ///< channel = node-ID of the silent node
  std::uint8_t life_guard_description = 0x10;  ///< channel 0
  std::uint8_t rpdo_timeout_description = 0x00;
  std::uint8_t bus_off_description = 0x00;
  std::uint16_t heartbeat_code = 0x8130;
  std::uint16_t life_guard_code = 0x8130;
  std::uint16_t rpdo_timeout_code = 0x8100;
  std::uint16_t bus_off_code = 0x8140;
  /// 1029h sub-index deciding the NMT reaction to a communication error (1 in every manual).
  std::uint8_t communication_behaviour_sub = 1;
  /// 1003h entries kept (the valve and power supply: 4; the data logger: 4; the encoder: see its README).
  std::uint8_t history_depth = 4;
};

/// A device error of the family: EMCY `code`, 1003h description/channel, 1001h bit 0 only.
canopen::ErrorEntry MakeFamilyEntry(std::uint16_t code, std::uint8_t description, std::uint8_t channel);

class FamilyErrorPolicy final : public canopen::ErrorPolicy {
 public:
  explicit FamilyErrorPolicy(ErrorConventions conventions) : conventions_(conventions) {}
  std::optional<canopen::CommErrorEncoding> Encode(const canopen::CommError& error) const override;
  const ErrorConventions& conventions() const { return conventions_; }

 private:
  ErrorConventions conventions_;
};

/// The stack options the conventions imply (1003h depth, cleared errors leave the list).
void ApplyConventions(const ErrorConventions& conventions, canopen::StackOptions& options);

}  // namespace canfleet::devices::family
