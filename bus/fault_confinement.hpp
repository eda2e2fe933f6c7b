#pragma once
/// @file The error counters and fault-confinement state of one CAN controller (ISO 11898-1 §12.1.4).
/// The broker keeps one per port; the node learns of changes through BusPort::OnStateChange.

#include <cstdint>
#include <optional>

#include "bus/bus_port.hpp"

namespace canfleet {

enum class TransmitError : std::uint8_t {
  kBit,  ///< bit error, stuff error, form error: TEC + 8
  kAck,  ///< no node acknowledged (alone on the bus)
};

class FaultConfinement {
 public:
  /// A frame this controller sent was acknowledged: TEC − 1.
  std::optional<ControllerEvent> OnTransmitSuccess();
  /// A transmission failed: TEC + 8. Exception (rule 3, ISO 11898-1 §12.1.4.2): an error-passive
  /// transmitter that sees an ACK error does not count it, so a node alone on a bus stops at
  /// error-passive (TEC 128) and never goes bus-off.
  std::optional<ControllerEvent> OnTransmitError(TransmitError error);
  /// A frame was received correctly: REC − 1, or back into 119..127 when above 127.
  std::optional<ControllerEvent> OnReceiveSuccess();
  /// A receive error was detected: REC + 1.
  std::optional<ControllerEvent> OnReceiveError();
  /// Bus-off recovery completed (128 × 11 recessive bits seen, or forced on command):
  /// counters reset, error-active.
  std::optional<ControllerEvent> Recover();
  /// Forces bus-off (fault injection): TEC set to 256.
  std::optional<ControllerEvent> ForceBusOff();

  ControllerState State() const { return state_; }
  std::uint16_t Tec() const { return tec_; }
  std::uint8_t Rec() const { return rec_; }
  ControllerEvent Snapshot() const { return {state_, tec_, rec_}; }

 private:
  /// Recomputes the state; returns an event when it changed.
  std::optional<ControllerEvent> Update();

  std::uint16_t tec_ = 0;
  std::uint8_t rec_ = 0;
  ControllerState state_ = ControllerState::kErrorActive;
};

}  // namespace canfleet
