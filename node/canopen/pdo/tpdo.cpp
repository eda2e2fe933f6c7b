#include "node/canopen/pdo/tpdo.hpp"

#include <algorithm>

namespace canfleet::canopen {

Tpdo::Tpdo(PdoContext& context, std::size_t number, Object& comm, Object* mapping)
    : ctx_(context),
      number_(number),
      config_(context.od, PdoDirection::kTransmit, comm, mapping),
      event_timer_(context.scheduler, [this] { Trigger(); }),
      inhibit_timer_(context.scheduler, [this] { OnInhibitEnd(); }) {}

void Tpdo::Reconfigure() {
  const PdoCommParams before = config_.comm();
  const PdoMapping mapping_before = config_.mapping();
  const bool usable_before = config_.Usable();
  config_.Reload();
  const PdoCommParams& now = config_.comm();
  const bool same_pdo = usable_before == config_.Usable() && before.cob_id_raw == now.cob_id_raw &&
                        before.type == now.type && before.inhibit == now.inhibit &&
                        before.sync_start == now.sync_start && mapping_before == config_.mapping();
  if (!same_pdo) {
    Restart();
  } else if (before.event_timer != now.event_timer && Active() && IsEventDriven(now.type)) {
    // CiA 301 §7.5.2.37 sub5 may be written while the PDO is valid: the new period starts now.
    if (now.event_timer.count() > 0) {
      event_timer_.StartAfter(now.event_timer);
    } else {
      event_timer_.Cancel();
    }
  }
}

void Tpdo::SetOperational(bool operational) {
  if (operational == operational_) return;
  operational_ = operational;
  Restart();
}

void Tpdo::Restart() {
  event_timer_.Cancel();
  inhibit_timer_.Cancel();
  // Both timers send this TPDO and nothing else: in virtual time, a node that does not listen to
  // it is not held back by them (Timer::Confine). A 29-bit identifier is not confined: acceptance
  // filters are for 11-bit identifiers only.
  const auto& cob_id = config_.comm().cob_id;
  const std::uint32_t key = cob_id.extended ? Timer::kUnconfined : cob_id.can_id;
  event_timer_.Confine(key);
  inhibit_timer_.Confine(key);
  event_pending_ = false;
  phase_ = SyncPhase::kFirst;
  countdown_ = 0;
  has_sample_ = false;
  last_transmission_.reset();
  const auto& comm = config_.comm();
  if (Active() && IsEventDriven(comm.type) && comm.event_timer.count() > 0)
    event_timer_.StartAfter(comm.event_timer);
}

bool Tpdo::OnRemoteRequest(const CanFrame& frame) {
  const auto& comm = config_.comm();
  if (!Active() || frame.id != comm.cob_id.can_id || frame.extended() != comm.cob_id.extended) return false;
  if (!comm.cob_id.rtr_allowed) return true;
  if (comm.type == kTransmissionRtrEvent) TransmitCurrent();
  if (comm.type == kTransmissionRtrSync && has_sample_) Transmit(sample_);
  return true;
}

void Tpdo::OnSync(std::uint8_t counter) {
  if (!Active()) return;
  const auto& comm = config_.comm();
  if (comm.type == kTransmissionSyncAcyclic) {
    if (event_pending_) TransmitCurrent();
    return;
  }
  if (comm.type <= kTransmissionSyncMaxCycle) {
    if (phase_ == SyncPhase::kFirst) {
      // The start value only means something when the SYNC carries a counter (1019h ≥ 2).
      phase_ = comm.sync_start != 0 && counter != 0 ? SyncPhase::kWaitStart : SyncPhase::kCounting;
      countdown_ = comm.type;
    }
    if (phase_ == SyncPhase::kWaitStart) {
      if (counter != comm.sync_start) return;
      phase_ = SyncPhase::kCounting;
      countdown_ = comm.type;
      TransmitCurrent();
      return;
    }
    if (--countdown_ == 0) {
      countdown_ = comm.type;
      TransmitCurrent();
    }
    return;
  }
  if (comm.type == kTransmissionRtrSync) {
    config_.mapping().Pack(sample_);
    has_sample_ = true;
  }
}

void Tpdo::OnEvent() {
  if (!Active()) return;
  const auto type = config_.comm().type;
  if (type == kTransmissionSyncAcyclic) event_pending_ = true;
  if (IsEventDriven(type)) Trigger();
}

// An event for an event-driven TPDO (application event or event timer), held back until the
// inhibit time since the last transmission has passed (CiA 301 §7.5.2.37 sub3).
void Tpdo::Trigger() {
  if (!Active()) return;
  const auto inhibit = config_.comm().inhibit;
  if (inhibit.count() > 0 && last_transmission_) {
    const TimePoint allowed = *last_transmission_ + inhibit;
    if (ctx_.scheduler.Now() < allowed) {
      event_pending_ = true;
      if (!inhibit_timer_.Armed()) inhibit_timer_.StartAt(allowed);
      return;
    }
  }
  TransmitCurrent();
}

void Tpdo::OnInhibitEnd() {
  if (event_pending_ && Active()) TransmitCurrent();
}

void Tpdo::TransmitCurrent() {
  std::array<std::uint8_t, 8> data;
  config_.mapping().Pack(data);
  Transmit(data);
}

void Tpdo::Transmit(const std::array<std::uint8_t, 8>& data) {
  const auto& comm = config_.comm();
  if (ctx_.tpdo_gate && !ctx_.tpdo_gate(number_, config_.mapping().Entries())) {
    // Vetoed by the device: nothing on the bus, but the timers run on as if it had been sent, so
    // the PDO resumes on its own period once the device lets it through.
    event_pending_ = false;
    if (IsEventDriven(comm.type) && comm.event_timer.count() > 0) event_timer_.StartAfter(comm.event_timer);
    return;
  }
  CanFrame frame;
  frame.id = comm.cob_id.can_id;
  frame.flags = comm.cob_id.extended ? CanFrame::kExtended : 0;
  frame.dlc = config_.mapping().Bytes();
  std::copy_n(data.begin(), frame.dlc, frame.data.begin());
  event_pending_ = false;
  inhibit_timer_.Cancel();
  last_transmission_ = ctx_.scheduler.Now();
  if (IsEventDriven(comm.type) && comm.event_timer.count() > 0) event_timer_.StartAfter(comm.event_timer);
  if (ctx_.port.Send(frame)) ++ctx_.counters.tpdo_sent;
}

}  // namespace canfleet::canopen
