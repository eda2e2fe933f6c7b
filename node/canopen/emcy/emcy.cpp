#include "node/canopen/emcy/emcy.hpp"

#include <algorithm>

namespace canfleet::canopen {

namespace {

using namespace std::chrono_literals;

constexpr std::uint16_t kErrorRegisterIndex = 0x1001;
constexpr std::uint16_t kErrorFieldIndex = 0x1003;
constexpr std::uint16_t kCobIdIndex = 0x1014;
constexpr std::uint16_t kInhibitTimeIndex = 0x1015;
/// Error reset or no error (CiA 301 §7.2.7.1 table 21).
constexpr std::uint16_t kErrorReset = 0x0000;
/// 1001h bit 6 is reserved and reads 0 (CiA 301 §7.5.2.2).
constexpr std::uint8_t kErrorRegisterReserved = 0x40;
/// Active errors before the list allocates; the five devices have at most a few dozen conditions.
constexpr std::size_t kActiveReserve = 32;

bool ValidNodeId(std::uint8_t id) {
  return id >= 1 && id <= 127;
}

}  // namespace

Emcy::Emcy(ObjectDictionary& od, BusPort& port, Scheduler& scheduler, EmcyOptions options)
    : od_(od), port_(port), scheduler_(scheduler), options_(options), inhibit_timer_(scheduler, [this] {
        OnInhibitExpired();
      }) {
  register_sub_ = od_.Find(kErrorRegisterIndex, 0);
  count_sub_ = od_.Find(kErrorFieldIndex, 0);
  if (count_sub_) {
    // Sub-index FFh is reserved for the object structure, so an error field has at most 254.
    for (unsigned sub = 1; sub <= 0xFE; ++sub) {
      SubObject* entry = od_.Find(kErrorFieldIndex, static_cast<std::uint8_t>(sub));
      if (!entry) break;
      entry_subs_.push_back(entry);
    }
  }
  history_capacity_ = entry_subs_.size();
  if (options_.max_history != 0) history_capacity_ = std::min(history_capacity_, options_.max_history);
  history_.reserve(history_capacity_);
  active_.reserve(kActiveReserve);

  cob_id_sub_ = od_.Find(kCobIdIndex, 0);
  if (cob_id_sub_) LoadCobId(static_cast<std::uint32_t>(DecodeUnsignedLe(cob_id_sub_->value)));
  LoadInhibitTime();
  InstallHooks();
  SyncRegister();
  SyncHistory();
  SyncCobId();
}

void Emcy::InstallHooks() {
  if (register_sub_) {
    // Read-only for SDO; anything else that writes it (a restore of defaults) is undone.
    register_sub_->AddListener([this](SubObject&, Origin) {
      if (!syncing_) SyncRegister();
    });
  }
  if (count_sub_) {
    // CiA 301 §7.5.2.4: writing 0 to sub-index 0 deletes the history; other values are refused.
    count_sub_->AddValidator([](const SubObject&, std::span<const std::uint8_t> data, Origin) {
      return DecodeUnsignedLe(data) == 0 ? SdoAbort::kNone : SdoAbort::kInvalidValue;
    });
    count_sub_->AddListener([this](SubObject& sub, Origin origin) {
      if (syncing_) return;
      // The device side (RestoreDefaults at reset communication, device code) does not edit the
      // history by writing the count: it is put back. ClearHistory() is the device's way.
      if (origin != Origin::kDevice && DecodeUnsignedLe(sub.value) == 0) {
        ClearHistory();
      } else {
        SyncHistory();
      }
    });
  }
  for (std::size_t i = 0; i < entry_subs_.size(); ++i) {
    SubObject& entry = *entry_subs_[i];
    // Entries are read-only even if a device file declares them rw.
    entry.AddValidator(
        [](const SubObject&, std::span<const std::uint8_t>, Origin) { return SdoAbort::kReadOnly; });
    entry.AddListener([this](SubObject&, Origin) {
      if (!syncing_) SyncHistory();
    });
    // Reading past the number of errors answers "no data available" (CANopenNode OD_read_1003).
    entry.AddReadHook(
        [this, i](SubObject&, Origin) { return i < history_.size() ? SdoAbort::kNone : SdoAbort::kNoData; });
  }
  if (cob_id_sub_) {
    cob_id_sub_->AddValidator([this](const SubObject&, std::span<const std::uint8_t> data, Origin) {
      return ValidateEmcyCobIdWrite(CobIdValue(), static_cast<std::uint32_t>(DecodeUnsignedLe(data)));
    });
    cob_id_sub_->AddListener([this](SubObject& sub, Origin) {
      if (syncing_) return;
      LoadCobId(static_cast<std::uint32_t>(DecodeUnsignedLe(sub.value)));
      SyncCobId();
    });
  }
  if (SubObject* inhibit = od_.Find(kInhibitTimeIndex, 0)) {
    inhibit->AddListener([this](SubObject&, Origin) { LoadInhibitTime(); });
  }
}

void Emcy::SetNodeId(std::uint8_t node_id) {
  node_id_ = node_id;
  if (!cob_id_.extended && ValidNodeId(node_id_) && cob_id_.can_id == kEmcyFunctionCode + node_id_) {
    cob_id_.can_id = kEmcyFunctionCode;
  }
  SyncCobId();
}

void Emcy::SetNmtState(NmtState state) {
  nmt_state_ = state;
  if (!EmcyAllowed(state)) DropQueue();
}

void Emcy::Raise(const ErrorEntry& error) {
  if (error.code == kErrorReset || IsActive(error.code, error.info)) return;
  active_.push_back(error);
  PushHistory(error.HistoryValue());
  RecomputeRegister();
  SyncRegister();
  SyncHistory();
  NotifyActiveChanged();
  Emit(error.code, error.msef);
}

void Emcy::Clear(std::uint16_t code, std::uint16_t info) {
  auto it = std::find_if(active_.begin(), active_.end(),
                         [&](const ErrorEntry& e) { return e.code == code && e.info == info; });
  if (it == active_.end()) return;
  const std::uint32_t value = it->HistoryValue();
  active_.erase(it);
  if (options_.remove_cleared_from_history) RemoveFromHistory(value);
  RecomputeRegister();
  SyncRegister();
  SyncHistory();
  NotifyActiveChanged();
  // CiA 301 §7.2.7.1 error state diagram: transition 5 (all errors gone) sends 0000h with the
  // (now empty) register; transition 3 (one of several gone) may send it with what remains.
  if (active_.empty() || options_.reset_emcy_on_partial_clear) Emit(kErrorReset, {});
}

void Emcy::ClearAll() {
  const bool had_active = !active_.empty();
  active_.clear();
  history_.clear();
  error_register_ = 0;
  DropQueue();
  last_transmit_.reset();
  SyncRegister();
  SyncHistory();
  if (had_active) NotifyActiveChanged();
}

void Emcy::NotifyActiveChanged() {
  for (auto& listener : active_listeners_)
    listener();
}

void Emcy::ClearHistory() {
  history_.clear();
  SyncHistory();
}

bool Emcy::IsActive(std::uint16_t code, std::uint16_t info) const {
  return std::any_of(active_.begin(), active_.end(),
                     [&](const ErrorEntry& e) { return e.code == code && e.info == info; });
}

// --- frames -------------------------------------------------------------------------------------

bool Emcy::FollowsNodeId(std::uint32_t can_id) const {
  return !cob_id_.extended && can_id == kEmcyFunctionCode;
}

std::uint32_t Emcy::CobIdValue() const {
  EmcyCobId c = cob_id_;
  if (FollowsNodeId(c.can_id) && ValidNodeId(node_id_)) c.can_id = kEmcyFunctionCode + node_id_;
  return c.Encode();
}

bool Emcy::MaySend() const {
  if (!EmcyAllowed(nmt_state_) || !cob_id_.valid) return false;
  if (FollowsNodeId(cob_id_.can_id)) return ValidNodeId(node_id_);
  return true;
}

void Emcy::Emit(std::uint16_t code, const std::array<std::uint8_t, 5>& msef) {
  if (!MaySend()) return;
  CanFrame frame;
  frame.dlc = 8;
  frame.data[0] = static_cast<std::uint8_t>(code);
  frame.data[1] = static_cast<std::uint8_t>(code >> 8);
  frame.data[2] = error_register_;
  std::copy(msef.begin(), msef.end(), frame.data.begin() + 3);
  const TimePoint now = scheduler_.Now();
  const bool inhibited = last_transmit_ && now < *last_transmit_ + inhibit_time_;
  if (queue_size_ == 0 && !inhibited && !held_by_bus_off_) {
    Transmit(frame);
    return;
  }
  if (queue_size_ == kQueueCapacity) {
    // Keep the latest state: the oldest waiting frame makes room.
    queue_head_ = (queue_head_ + 1) % kQueueCapacity;
    --queue_size_;
    ++overruns_;
  }
  queue_[(queue_head_ + queue_size_) % kQueueCapacity] = frame;
  ++queue_size_;
  if (!inhibit_timer_.Armed() && !held_by_bus_off_) inhibit_timer_.StartAt(*last_transmit_ + inhibit_time_);
}

void Emcy::Transmit(CanFrame frame) {
  const std::uint32_t cob_id = CobIdValue();
  frame.id = cob_id & (cob_id_.extended ? CanFrame::kMaxExtendedId : CanFrame::kMaxStandardId);
  frame.flags = cob_id_.extended ? CanFrame::kExtended : 0;
  // The inhibit time runs from the attempt: a controller that refuses the frame (bus-off) does
  // not make the producer send faster.
  last_transmit_ = scheduler_.Now();
  if (!port_.Send(frame)) {
    // A bus-off controller refuses everything; the frame waits at the head of the queue for
    // OnBusOffEnded (a full queue or an invalid frame loses it, as before).
    if (port_.State() == ControllerState::kBusOff && queue_size_ < kQueueCapacity) {
      queue_head_ = (queue_head_ + kQueueCapacity - 1) % kQueueCapacity;
      queue_[queue_head_] = frame;
      ++queue_size_;
      held_by_bus_off_ = true;
      inhibit_timer_.Cancel();
    }
    return;
  }
  last_sent_ = frame;
  if (on_sent_) on_sent_(frame);
}

void Emcy::OnBusOffEnded() {
  if (!held_by_bus_off_) return;
  held_by_bus_off_ = false;
  if (queue_size_ == 0) return;
  const TimePoint now = scheduler_.Now();
  inhibit_timer_.StartAt(last_transmit_ ? std::max(now, *last_transmit_ + inhibit_time_) : now);
}

void Emcy::OnInhibitExpired() {
  if (queue_size_ == 0 || held_by_bus_off_) return;
  if (!MaySend()) {
    DropQueue();
    return;
  }
  CanFrame frame = queue_[queue_head_];
  queue_head_ = (queue_head_ + 1) % kQueueCapacity;
  --queue_size_;
  Transmit(frame);
  if (queue_size_ > 0) inhibit_timer_.StartAt(*last_transmit_ + inhibit_time_);
}

void Emcy::DropQueue() {
  queue_head_ = 0;
  queue_size_ = 0;
  held_by_bus_off_ = false;
  inhibit_timer_.Cancel();
}

// --- configuration ------------------------------------------------------------------------------

void Emcy::LoadCobId(std::uint32_t value) {
  cob_id_ = EmcyCobId::Decode(value);
  // CANopenNode keeps "80h + own node-ID" as the default, which follows later node-ID changes.
  if (!cob_id_.extended && ValidNodeId(node_id_) && cob_id_.can_id == kEmcyFunctionCode + node_id_) {
    cob_id_.can_id = kEmcyFunctionCode;
  }
  if (!cob_id_.valid) DropQueue();
}

void Emcy::LoadInhibitTime() {
  const SubObject* sub = od_.Find(kInhibitTimeIndex, 0);
  // CiA 301 §7.5.2.18: multiples of 100 µs; 0 disables the inhibit time.
  inhibit_time_ = sub ? static_cast<std::int64_t>(DecodeUnsignedLe(sub->value)) * 100us : Duration{0};
  if (inhibit_timer_.Armed() && last_transmit_) {
    inhibit_timer_.StartAt(std::max(scheduler_.Now(), *last_transmit_ + inhibit_time_));
  }
}

// --- bookkeeping --------------------------------------------------------------------------------

void Emcy::PushHistory(std::uint32_t value) {
  if (history_capacity_ == 0) return;
  if (history_.size() == history_capacity_) history_.pop_back();
  history_.insert(history_.begin(), value);
}

void Emcy::RemoveFromHistory(std::uint32_t value) {
  auto it = std::find(history_.begin(), history_.end(), value);
  if (it != history_.end()) history_.erase(it);
}

void Emcy::RecomputeRegister() {
  std::uint8_t reg = 0;
  for (const auto& e : active_)
    reg |= e.register_bits;
  if (!active_.empty()) reg |= kErrorRegisterGeneric;
  error_register_ = static_cast<std::uint8_t>(reg & ~kErrorRegisterReserved);
}

void Emcy::Store(SubObject& sub, std::uint64_t value) {
  const std::size_t size = FixedSize(sub.type).value_or(0);
  if (size == 0 || size > 8) return;
  std::array<std::uint8_t, 8> bytes{};
  for (std::size_t i = 0; i < size; ++i)
    bytes[i] = static_cast<std::uint8_t>(value >> (8 * i));
  if (sub.value.size() == size && std::equal(sub.value.begin(), sub.value.end(), bytes.begin())) return;
  const bool was_syncing = syncing_;
  syncing_ = true;
  od_.Write(sub, std::span<const std::uint8_t>(bytes.data(), size), Origin::kDevice);
  syncing_ = was_syncing;
}

void Emcy::SyncRegister() {
  if (register_sub_) Store(*register_sub_, error_register_);
}

void Emcy::SyncHistory() {
  if (count_sub_) Store(*count_sub_, history_.size());
  for (std::size_t i = 0; i < entry_subs_.size(); ++i) {
    Store(*entry_subs_[i], i < history_.size() ? history_[i] : 0);
  }
}

void Emcy::SyncCobId() {
  if (cob_id_sub_) Store(*cob_id_sub_, CobIdValue());
}

}  // namespace canfleet::canopen
