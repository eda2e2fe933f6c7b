#include "node/canopen/pdo/rpdo.hpp"

namespace canfleet::canopen {

Rpdo::Rpdo(PdoContext& context, std::size_t number, Object& comm, Object* mapping)
    : ctx_(context),
      number_(number),
      config_(context.od, PdoDirection::kReceive, comm, mapping),
      deadline_(context.scheduler, [this] { OnDeadline(); }) {}

void Rpdo::Reconfigure() {
  const PdoCommParams before = config_.comm();
  const PdoMapping mapping_before = config_.mapping();
  const bool usable_before = config_.Usable();
  config_.Reload();
  const PdoCommParams& now = config_.comm();
  const bool same_pdo = usable_before == config_.Usable() && before.cob_id_raw == now.cob_id_raw &&
                        before.type == now.type && mapping_before == config_.mapping();
  if (!now.cob_id.valid) {
    SetLengthError(LengthError::kNone);
    ClearTimeout();
  }
  if (now.event_timer.count() == 0) ClearTimeout();
  if (!same_pdo) {
    Restart();
  } else if (before.event_timer != now.event_timer && last_reception_) {
    if (now.event_timer.count() > 0) {
      deadline_.StartAt(*last_reception_ + now.event_timer);
    } else {
      deadline_.Cancel();
    }
  }
}

void Rpdo::SetOperational(bool operational) {
  if (operational == operational_) return;
  operational_ = operational;
  Restart();
}

void Rpdo::Restart() {
  deadline_.Cancel();
  last_reception_.reset();
  pending_ = false;
}

bool Rpdo::OnFrame(const CanFrame& frame) {
  const auto& comm = config_.comm();
  if (!Active() || frame.id != comm.cob_id.can_id || frame.extended() != comm.cob_id.extended) return false;
  ++ctx_.counters.rpdo_received;
  const std::uint8_t needed = config_.mapping().Bytes();
  if (needed > 0) {
    if (frame.dlc < needed) {
      SetLengthError(LengthError::kTooShort);
      return true;
    }
    SetLengthError(frame.dlc > needed ? LengthError::kTooLong : LengthError::kNone);
  }
  if (comm.event_timer.count() > 0) {
    last_reception_ = ctx_.scheduler.Now();
    deadline_.StartAt(*last_reception_ + comm.event_timer);
  }
  ClearTimeout();
  if (IsSynchronous(comm.type)) {
    if (!ctx_.InsideSyncWindow()) return true;
    pending_data_ = frame.data;
    pending_ = true;
    return true;
  }
  Apply(frame.data);
  return true;
}

void Rpdo::OnSync() {
  if (!pending_) return;
  pending_ = false;
  if (Active()) Apply(pending_data_);
}

void Rpdo::Apply(const std::array<std::uint8_t, 8>& data) {
  config_.mapping().Unpack(ctx_.od, std::span<const std::uint8_t>(data.data(), config_.mapping().Bytes()));
  ++ctx_.counters.rpdo_applied;
}

void Rpdo::OnDeadline() {
  if (!Active() || timeout_active_) return;
  timeout_active_ = true;
  Report(CommErrorKind::kRpdoTimeout, true);
}

void Rpdo::ClearTimeout() {
  if (!timeout_active_) return;
  timeout_active_ = false;
  Report(CommErrorKind::kRpdoTimeout, false);
}

void Rpdo::SetLengthError(LengthError error) {
  if (error == length_error_) return;
  if (length_error_ != LengthError::kNone) {
    Report(
        length_error_ == LengthError::kTooShort ? CommErrorKind::kRpdoTooShort : CommErrorKind::kRpdoTooLong,
        false);
  }
  length_error_ = error;
  if (error != LengthError::kNone) {
    Report(error == LengthError::kTooShort ? CommErrorKind::kRpdoTooShort : CommErrorKind::kRpdoTooLong,
           true);
  }
}

void Rpdo::Report(CommErrorKind kind, bool active) {
  // CommError carries the RPDO number in one byte; numbers above 255 are reported as 0.
  const auto detail = static_cast<std::uint8_t>(number_ <= 0xFF ? number_ : 0);
  ctx_.errors.OnCommError({kind, detail}, active);
}

}  // namespace canfleet::canopen
