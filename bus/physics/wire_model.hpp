#pragma once
/// @file The rules of a CAN wire beyond the length of a frame (frame_timing.hpp): who wins
/// arbitration, who acknowledges, how long a failed transfer occupies the bus, what a transmitter
/// counts for it, how long an error-passive transmitter waits, and when a bus-off controller
/// recovers. The broker applies them to its ports (orchestrator/broker/virtual_bus.hpp); with
/// fault_confinement.hpp (the counters of one controller) this folder is the whole physics.
/// Lengths are in bit times.

#include <cstdint>

#include "bus/can_frame.hpp"
#include "bus/physics/fault_confinement.hpp"
#include "bus/physics/frame_timing.hpp"

namespace canfleet {

/// The bit rates of classical CAN the model accepts (ISO 11898-2 high-speed: up to 1 Mbit/s;
/// 10 kbit/s is the lowest rate of CiA 301's bit timing table).
inline constexpr std::uint32_t kMinBitrate = 10'000;
inline constexpr std::uint32_t kMaxBitrate = 1'000'000;

/// The arbitration field of `frame` as a 32-bit number whose order is the wire's order: of two
/// frames, the one with the smaller key wins arbitration (ISO 11898-1:2015 §6.3 bus access method;
/// arbitration field of §10.4: dominant 0 overwrites recessive 1, so the first differing bit decides).
///
/// Bits, most significant first, as transmitted after SOF:
///
///     31..21  base identifier (ID-28..ID-18; the whole 11-bit identifier of a base frame)
///     20      RTR of a base frame, SRR (always recessive) of an extended frame
///     19      IDE: dominant (0) for a base frame, recessive (1) for an extended frame
///     18..1   identifier extension (ID-17..ID-0), 0 for a base frame
///     0       RTR of an extended frame, 0 for a base frame
///
/// Consequences: a data frame beats a remote frame with the same identifier (RTR); a base-format
/// data frame beats an extended frame with the same base identifier (RTR dominant vs SRR
/// recessive); a base-format remote frame still beats it (IDE). A base frame's arbitration ends at
/// IDE, so its bits 18..0 are 0 and two base frames that tie there are the same identifier.
constexpr std::uint32_t ArbitrationKey(const CanFrame& frame) {
  const std::uint32_t rtr = (frame.flags & CanFrame::kRemote) != 0 ? 1U : 0U;
  if ((frame.flags & CanFrame::kExtended) != 0) {
    const std::uint32_t base = (frame.id >> 18) & 0x7FFU;
    const std::uint32_t extension = frame.id & 0x3FFFFU;
    return base << 21 | 1U << 20 | 1U << 19 | extension << 1 | rtr;
  }
  return (frame.id & 0x7FFU) << 21 | rtr << 20;
}

/// Whether a controller acknowledges the frames of others: any controller that is not bus-off
/// does, error-passive ones too (ISO 11898-1:2015 §6.10); a listen-only one never drives the bus.
constexpr bool Acknowledges(ControllerState state, bool listen_only) {
  return !listen_only && state != ControllerState::kBusOff;
}

/// A transfer that ends in an ACK error: the transmitter sees no dominant ACK slot and starts its
/// error flag at the next bit (ISO 11898-1:2015 §6.10 ACK, §6.9 error signalling). After the stuffed
/// region: CRC delimiter 1, ACK slot 1, error flag 6, error delimiter 8, intermission 3.
inline constexpr std::uint32_t kAckErrorTailBits = 1 + 1 + 6 + 8 + 3;

/// A transfer destroyed by a CRC error (the broker's model of a corrupted frame): receivers start
/// their error flag at the bit after the ACK delimiter (ISO 11898-1:2015 §6.8 error detection, §6.9
/// error signalling). After the stuffed region: CRC delimiter 1,
/// ACK slot 1, ACK delimiter 1, error flag 6, error delimiter 8, intermission 3. Superposed error
/// flags (up to 12 bits when nodes detect the error at different bits) are not modelled.
inline constexpr std::uint32_t kCrcErrorTailBits = 1 + 1 + 1 + 6 + 8 + 3;

/// A transfer that no controller at the transmitter's bit rate acknowledges while controllers at
/// another rate are on the bus: to them the frame is noise, and the first violation of the bit
/// stuffing rule they sample (six equal bits, ISO 11898-1:2015 §10.5 bit stuffing, §10.9.3 stuff
/// error) makes them send an error flag, which the transmitter sees as a bit error (§10.9.2). The
/// broker's model of it, in bit times of the transmitter's rate: start of frame 1, six bits to the
/// stuff error, error flag 6, error delimiter 8, intermission 3. Where exactly a controller at
/// another rate detects its first error depends on both rates and on the frame; six bits is the
/// earliest a stuff error can occur, and the attempt is short whatever the frame.
inline constexpr std::uint32_t kRateErrorAttemptBits = 1 + 6 + 6 + 8 + 3;

/// After transmitting a frame, an error-passive node sends 8 recessive bits (suspend transmission)
/// following the intermission before it may start another transfer; other nodes may start in the
/// meantime (ISO 11898-1:2015 §10.4, interframe space: suspend transmission; §6.14 error-passive).
inline constexpr std::uint32_t kSuspendTransmissionBits = 8;

/// How a transfer ended on the wire.
enum class TransferOutcome : std::uint8_t {
  kOk,        ///< acknowledged, valid for everyone
  kAckError,  ///< nobody acknowledged (the transmitter is alone on the bus)
  kCrcError,  ///< destroyed by an error frame (fault injection)
  /// Destroyed by the error flags of controllers at another bit rate; nobody at the transmitter's
  /// rate acknowledged it (kRateErrorAttemptBits).
  kRateError,
};

/// Bus occupancy of one transfer attempt of `frame`, including the intermission that follows it.
inline std::uint32_t AttemptBits(const CanFrame& frame, TransferOutcome outcome) {
  const FrameBits bits = CountFrameBits(frame);
  switch (outcome) {
    case TransferOutcome::kAckError:
      return bits.unstuffed + bits.stuff + kAckErrorTailBits;
    case TransferOutcome::kCrcError:
      return bits.unstuffed + bits.stuff + kCrcErrorTailBits;
    case TransferOutcome::kRateError:
      return kRateErrorAttemptBits;
    case TransferOutcome::kOk:
      break;
  }
  return bits.total();
}

/// What the transmitter of a failed transfer counts (ISO 11898-1:2015 §12.1.4.2 rule 3 and its
/// exception 1, see FaultConfinement::OnTransmitError). Only for a failed outcome.
constexpr TransmitError TransmitErrorOf(TransferOutcome outcome) {
  return outcome == TransferOutcome::kAckError ? TransmitError::kAck : TransmitError::kBit;
}

/// When a transmitter in `state` whose transfer ended at `end` may start its next one: at once,
/// or after suspend transmission when it is error-passive. Bus times.
inline BusTime ReadyAfterTransfer(ControllerState state, BusTime end, std::uint32_t bitrate) {
  return state == ControllerState::kErrorPassive ? end + BitTime(kSuspendTransmissionBits, bitrate) : end;
}

/// When a controller that went bus-off at `at` has seen 128 occurrences of 11 recessive bits and
/// recovers (ISO 11898-1:2015 §12.1.4.2), counted as 1408 bit times from the end of the error
/// frame that caused it. Simplification: on a busy bus a real controller needs longer (each frame
/// supplies about one of the 128 occurrences).
inline BusTime RecoveryAttemptAt(BusTime at, std::uint32_t bitrate) {
  return at + BitTime(kBusOffRecoveryBits, bitrate);
}

}  // namespace canfleet
