#pragma once
/// @file One receive PDO (CiA 301 v4.2 §7.2.2; 1400h+/1600h+).
///
/// RPDO frame, COB-ID from sub1 (29-bit if bit 29), DLC ≥ mapped bytes:
///   bytes 0..n-1: the mapped objects in entry order, little-endian, packed from bit 0

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>

#include "bus/can_frame.hpp"
#include "clock/scheduler.hpp"
#include "node/canopen/pdo/pdo_config.hpp"
#include "node/canopen/pdo/pdo_context.hpp"

namespace canfleet::canopen {

/// Reception of one RPDO, in operational only:
/// - DLC shorter than the mapping: nothing is written, {kRpdoTooShort, n} (EMCY 8210h); such a
///   frame does not count for the deadline. Longer: written, {kRpdoTooLong, n} (EMCY 8220h).
///   Each length error is reported once when it appears and cleared by the next frame of the
///   right length (CANopenNode `CO_PDO_receive`). An RPDO with nothing mapped takes any DLC.
/// - Types 0–240: the data is kept and written at the next SYNC (the last frame before it wins);
///   a frame received outside the synchronous window (1007h) is dropped (CiA 301 §7.5.2.7).
///   Types 254/255: written at once.
/// - Deadline (sub5 event timer ≠ 0): monitoring starts with the first frame received in
///   operational (CANopenNode; the manuals treat a timeout as an error "once received"); a gap
///   longer than sub5 ms reports {kRpdoTimeout, n} once (EMCY 8250h, or 8100h on these devices),
///   the next frame clears it. Leaving operational stops monitoring without clearing a pending
///   timeout (1029h may be what took the node out of operational); disabling the RPDO or setting
///   sub5 to 0 clears it.
class Rpdo {
 public:
  Rpdo(PdoContext& context, std::size_t number, Object& comm, Object* mapping);
  Rpdo(const Rpdo&) = delete;
  Rpdo& operator=(const Rpdo&) = delete;

  std::size_t number() const { return number_; }
  PdoConfig& config() { return config_; }
  const PdoConfig& config() const { return config_; }
  /// Valid and usable, in whatever NMT state: frames of its COB-ID may be taken (an acceptance
  /// filter asks; it follows the configuration only, so that an NMT start, which no reply follows,
  /// never leaves a filter behind in real time).
  bool Listening() const { return config_.Usable(); }

  /// After a write of either record: re-reads it. A new event timer value moves the running
  /// deadline to last reception + new value; any other change restarts reception.
  void Reconfigure();
  void SetOperational(bool operational);
  /// A data frame: true if it carries this RPDO's identifier and the RPDO is in use.
  bool OnFrame(const CanFrame& frame);
  void OnSync();

 private:
  enum class LengthError : std::uint8_t { kNone, kTooShort, kTooLong };

  bool Active() const { return operational_ && config_.Usable(); }
  void Restart();
  void OnDeadline();
  void SetLengthError(LengthError error);
  void ClearTimeout();
  void Apply(const std::array<std::uint8_t, 8>& data);
  void Report(CommErrorKind kind, bool active);

  PdoContext& ctx_;
  std::size_t number_;
  PdoConfig config_;
  bool operational_ = false;
  bool timeout_active_ = false;
  LengthError length_error_ = LengthError::kNone;
  bool pending_ = false;  // types 0–240: data waiting for the SYNC
  std::array<std::uint8_t, 8> pending_data_{};
  std::optional<TimePoint> last_reception_;
  Timer deadline_;
};

}  // namespace canfleet::canopen
