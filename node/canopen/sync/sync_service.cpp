#include "node/canopen/sync/sync_service.hpp"

#include <chrono>

namespace canfleet::canopen {

namespace {
std::uint64_t ValueOf(const SubObject* sub) {
  return sub ? DecodeUnsignedLe(sub->value) : 0;
}
}  // namespace

SyncService::SyncService(ObjectDictionary& od, BusPort& port, Scheduler& scheduler, CommErrorSink& errors)
    : port_(port),
      scheduler_(scheduler),
      errors_(errors),
      cob_id_(od.Find(kCobIdSyncIndex, 0)),
      period_(od.Find(kCommunicationCyclePeriodIndex, 0)),
      window_(od.Find(kSyncWindowLengthIndex, 0)),
      overflow_(od.Find(kSyncCounterOverflowIndex, 0)),
      producer_timer_(scheduler, [this] { Produce(); }) {
  auto reconfigure = [this](SubObject&, Origin) { Configure(); };
  if (cob_id_) {
    cob_id_->AddValidator([](const SubObject& sub, std::span<const std::uint8_t> data, Origin) {
      return CheckSyncCobIdWrite(static_cast<std::uint32_t>(DecodeUnsignedLe(sub.value)),
                                 static_cast<std::uint32_t>(DecodeUnsignedLe(data)));
    });
    cob_id_->AddListener(reconfigure);
  }
  if (overflow_) {
    overflow_->AddValidator([this](const SubObject&, std::span<const std::uint8_t> data, Origin) {
      return CheckSyncCounterOverflowWrite(static_cast<std::uint8_t>(DecodeUnsignedLe(data)), PeriodUs());
    });
    overflow_->AddListener(reconfigure);
  }
  if (period_) period_->AddListener(reconfigure);
  Configure();
}

std::uint32_t SyncService::PeriodUs() const {
  return static_cast<std::uint32_t>(ValueOf(period_));
}
std::uint8_t SyncService::Overflow() const {
  return static_cast<std::uint8_t>(ValueOf(overflow_));
}

void SyncService::SetNmtState(NmtState state) {
  allowed_ = SyncAllowed(state);
  Configure();
}

// Re-reads 1005h/1006h/1019h and starts, re-arms or stops the producer accordingly.
void SyncService::Configure() {
  cob_ = cob_id_ ? SyncCobId::Decode(static_cast<std::uint32_t>(ValueOf(cob_id_))) : SyncCobId{};
  const std::uint32_t period_us = PeriodUs();
  const std::uint8_t overflow = Overflow();
  const bool produce = allowed_ && cob_.producer && period_us != 0;
  const auto period = std::chrono::microseconds(period_us);
  if (overflow != active_overflow_) next_counter_ = 1;
  if (!produce) {
    producer_timer_.Cancel();
  } else if (!producer_timer_.Armed()) {
    next_counter_ = 1;
    producer_timer_.StartAfter(period);
  } else if (period_us != active_period_us_) {
    producer_timer_.StartAfter(period);
  }
  active_period_us_ = period_us;
  active_overflow_ = overflow;
}

// Producer (CiA 301 §7.2.5): the counter is incremented with every SYNC sent and wraps from
// 1019h back to 1.
void SyncService::Produce() {
  producer_timer_.StartAt(producer_timer_.Deadline() + std::chrono::microseconds(active_period_us_));
  CanFrame frame;
  frame.id = cob_.can_id;
  frame.flags = cob_.extended ? CanFrame::kExtended : 0;
  std::uint8_t counter = 0;
  if (SyncCounterInUse(active_overflow_)) {
    counter = next_counter_;
    next_counter_ = counter >= active_overflow_ ? 1 : static_cast<std::uint8_t>(counter + 1);
    frame.dlc = 1;
    frame.data[0] = counter;
  }
  port_.Send(frame);
  Dispatch(counter);
}

bool SyncService::OnFrame(const CanFrame& frame) {
  if (!allowed_ || frame.remote() || frame.error()) return false;
  if (frame.id != cob_.can_id || frame.extended() != cob_.extended) return false;
  if (cob_.producer) return true;
  const bool with_counter = SyncCounterInUse(active_overflow_);
  // CiA 301 §7.2.5 and 1019h: DLC 1 with the counter when 1019h > 1, else DLC 0 (EMCY 8240h otherwise).
  if (frame.dlc != (with_counter ? 1 : 0)) {
    if (!length_error_) {
      length_error_ = true;
      errors_.OnCommError({CommErrorKind::kSyncLength, 0}, true);
    }
    return true;
  }
  if (length_error_) {
    length_error_ = false;
    errors_.OnCommError({CommErrorKind::kSyncLength, 0}, false);
  }
  Dispatch(with_counter ? frame.data[0] : 0);
  return true;
}

void SyncService::Dispatch(std::uint8_t counter) {
  last_sync_ = scheduler_.Now();
  // By index: a listener may add another listener.
  for (std::size_t i = 0; i < listeners_.size(); ++i)
    listeners_[i](counter);
}

void SyncService::OnSync(std::function<void(std::uint8_t counter)> listener) {
  if (listener) listeners_.push_back(std::move(listener));
}

// CiA 301 §7.5.2.7: synchronous PDOs belong to the window of 1007h µs that opens with each SYNC.
bool SyncService::InsideWindow() const {
  const std::uint64_t window_us = ValueOf(window_);
  if (window_us == 0) return true;
  if (!last_sync_) return false;
  return scheduler_.Now() - *last_sync_ <= std::chrono::microseconds(window_us);
}

}  // namespace canfleet::canopen
