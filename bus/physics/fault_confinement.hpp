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
  /// While an error-passive hold is on (HoldErrorPassive), TEC never falls below this.
  static constexpr std::uint16_t kErrorPassiveTec = 128;
  /// The TEC a released hold leaves: the highest error-active value (see HoldErrorPassive).
  static constexpr std::uint16_t kReleasedTec = 127;

  /// A frame this controller sent was acknowledged: TEC − 1.
  std::optional<ControllerEvent> OnTransmitSuccess();
  /// A transmission failed: TEC + 8. Exception (rule 3, ISO 11898-1 §12.1.4.2): an error-passive
  /// transmitter that sees an ACK error does not count it, so a node alone on a bus stops at
  /// error-passive (TEC 128) and never goes bus-off.
  std::optional<ControllerEvent> OnTransmitError(TransmitError error);
  /// A frame was received correctly: REC − 1, or back into 119..127 when above 127.
  std::optional<ControllerEvent> OnReceiveSuccess() {
    if (ReceiveSuccessChangesNothing()) return std::nullopt;
    return CountReceiveSuccess();
  }
  /// True when OnReceiveSuccess would change nothing: error-active with REC 0, the state of almost
  /// every receiver on a healthy bus. The broker calls OnReceiveSuccess for every receiver of every
  /// frame; testing this first keeps that loop free of the call and of the std::optional it
  /// returns (building one on the stack and reading it back cost a store-forwarding stall per
  /// receiver: most of the broker's time at 32 ports).
  bool ReceiveSuccessChangesNothing() const { return rec_ == 0 && state_ == ControllerState::kErrorActive; }
  /// A receive error was detected: REC + 1.
  std::optional<ControllerEvent> OnReceiveError();
  /// Bus-off recovery completed (128 × 11 recessive bits seen, or forced on command):
  /// counters reset, error-active (error-passive with TEC 128 while a hold is on).
  std::optional<ControllerEvent> Recover();
  /// Forces bus-off (fault injection): TEC set to 256.
  std::optional<ControllerEvent> ForceBusOff();

  /// Fault injection: holds the controller error-passive, as a node with a marginal transceiver
  /// that keeps failing some of its own transmissions would be.
  ///
  /// On: TEC is raised to 128 at once (error-passive now, with an event, unless it already was or
  /// is bus-off), and from then on never falls below 128: successful transmissions do not bring
  /// the controller back to error-active. Errors still count, so more than 255 is still bus-off;
  /// a recovery from bus-off while held ends at TEC 128, error-passive.
  ///
  /// Off: TEC is set to min(TEC, 127) and REC is left alone, so the controller is error-active
  /// again (with an event) unless REC ≥ 128 keeps it passive; a bus-off controller stays bus-off
  /// and recovers as usual. 127 is the value a real controller has at the moment it leaves
  /// error-passive (one success below the threshold); it then counts down with every success. A
  /// TEC of 0 would also erase the errors that the hold stood for, and anything in between is
  /// arbitrary.
  ///
  /// Returns the state change, if any. Turning the hold on (off) when it is on (off) does nothing.
  std::optional<ControllerEvent> HoldErrorPassive(bool on);
  bool ErrorPassiveHeld() const { return hold_passive_; }

  ControllerState State() const { return state_; }
  std::uint16_t Tec() const { return tec_; }
  std::uint8_t Rec() const { return rec_; }
  ControllerEvent Snapshot() const { return {state_, tec_, rec_}; }

 private:
  /// The slow path of OnReceiveSuccess.
  std::optional<ControllerEvent> CountReceiveSuccess();
  /// Recomputes the state; returns an event when it changed.
  std::optional<ControllerEvent> Update();

  std::uint16_t tec_ = 0;
  std::uint8_t rec_ = 0;
  ControllerState state_ = ControllerState::kErrorActive;
  bool hold_passive_ = false;
};

}  // namespace canfleet
