#pragma once
/// @file One transmit PDO (CiA 301 v4.2 §7.2.2; 1800h+/1A00h+).
///
/// TPDO frame, COB-ID from sub1 (29-bit if bit 29), DLC = mapped bytes:
///   bytes 0..DLC-1: the mapped objects in entry order, little-endian, packed from bit 0

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>

#include "bus/can_frame.hpp"
#include "clock/scheduler.hpp"
#include "node/canopen/pdo/pdo_config.hpp"
#include "node/canopen/pdo/pdo_context.hpp"

namespace canfleet::canopen {

/// When a TPDO is sent, by transmission type (CiA 301 §7.2.2, §7.5.2.37):
/// - 0: at the first SYNC after an event (NotifyChanged/RequestTpdo), data sampled at that SYNC.
/// - 1–240: at every n-th SYNC. Without a SYNC start value (sub6 = 0, or SYNC without counter)
///   the n-th SYNC after the TPDO became active is the first; with one, the first SYNC whose counter
///   equals it (CANopenNode `CO_TPDO_process`), then every n-th.
/// - 252: data sampled at each SYNC, sent on RTR (nothing before the first SYNC).
/// - 253: sent on RTR with current data. RTR-only types need COB-ID bit 30 = 0.
/// - 254/255: at each event and at the event timer (sub5), which restarts with every
///   transmission. The inhibit time (sub3) after a transmission delays an event to its end, never
///   drops it; events meanwhile coalesce into one frame with the data of its sending time.
/// Entering operational starts the event timer (first periodic frame one period later); it sends
/// nothing by itself (CANopenNode sends at once; the device can call RequestTpdo for that).
/// A TPDO with no mapped bits sends nothing.
class Tpdo {
 public:
  Tpdo(PdoContext& context, std::size_t number, Object& comm, Object* mapping);
  Tpdo(const Tpdo&) = delete;
  Tpdo& operator=(const Tpdo&) = delete;

  std::size_t number() const { return number_; }
  PdoConfig& config() { return config_; }
  const PdoConfig& config() const { return config_; }
  /// Valid, usable and mapped, in whatever NMT state: remote frames of its COB-ID may be taken
  /// (an acceptance filter asks; it follows the configuration only, as Rpdo::Listening).
  bool Listening() const { return config_.Usable() && config_.mapping().Bits() > 0; }

  /// After a write of either record: re-reads it. A new event timer value re-arms the timer from
  /// now; any other change restarts the TPDO (timers, SYNC count, pending events).
  void Reconfigure();
  void SetOperational(bool operational);
  /// A remote frame: true if it carries this TPDO's identifier (answered if the type is 252/253
  /// and RTR is allowed).
  bool OnRemoteRequest(const CanFrame& frame);
  void OnSync(std::uint8_t counter);
  /// An application event (a mapped object changed, or the device asks for this TPDO).
  void OnEvent();
  bool Maps(const SubObject& sub) const { return config_.mapping().Maps(sub); }

 private:
  enum class SyncPhase : std::uint8_t { kFirst, kWaitStart, kCounting };

  bool Active() const { return operational_ && config_.Usable() && config_.mapping().Bits() > 0; }
  void Restart();
  void Trigger();
  void OnInhibitEnd();
  void TransmitCurrent();
  void Transmit(const std::array<std::uint8_t, 8>& data);

  PdoContext& ctx_;
  std::size_t number_;
  PdoConfig config_;
  bool operational_ = false;
  bool event_pending_ = false;  // type 0: until the next SYNC; 254/255: until the inhibit time ends
  SyncPhase phase_ = SyncPhase::kFirst;
  std::uint8_t countdown_ = 0;
  bool has_sample_ = false;  // type 252
  std::array<std::uint8_t, 8> sample_{};
  std::optional<TimePoint> last_transmission_;
  Timer event_timer_;
  Timer inhibit_timer_;
};

}  // namespace canfleet::canopen
