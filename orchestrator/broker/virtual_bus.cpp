#include "orchestrator/broker/virtual_bus.hpp"

#include <algorithm>
#include <atomic>
#include <stdexcept>
#include <string>
#include <utility>

namespace canfleet::broker::detail {

namespace {

/// The shortest transfer: base format, DLC 0, no stuff bit (34 + tail 10 + intermission 3).
constexpr double kShortestTransferBits = 47;

BusConfig Validated(BusConfig config) {
  if (config.name.empty()) throw std::invalid_argument("bus name must not be empty");
  if (config.bitrate < kMinBitrate || config.bitrate > kMaxBitrate)
    throw std::invalid_argument("bus " + config.name + ": bitrate " + std::to_string(config.bitrate) +
                                " outside 10000..1000000 bit/s");
  if (config.tx_queue_capacity == 0)
    throw std::invalid_argument("bus " + config.name + ": TX queue capacity must be at least 1");
  if (config.stats_window <= Duration::zero())
    throw std::invalid_argument("bus " + config.name + ": statistics window must be positive");
  return config;
}

/// Enough records for a full window of the shortest transfers (paced); a fixed ring on an unpaced
/// bus, whose rate has no upper bound (the figures then cover the most recent records).
std::size_t LogCapacity(const BusConfig& config) {
  constexpr std::size_t kUnpaced = std::size_t{1} << 16;
  constexpr double kMax = static_cast<double>(std::size_t{1} << 22);
  if (!config.paced) return kUnpaced;
  const double window_bits = std::chrono::duration<double>(config.stats_window).count() * config.bitrate;
  return static_cast<std::size_t>(std::min(window_bits / kShortestTransferBits + 16, kMax));
}

/// SharedRound ids: unique across the buses (and brokers) of the process.
std::uint64_t NextRoundId() {
  static std::atomic<std::uint64_t> next{1};
  return next.fetch_add(1, std::memory_order_relaxed);
}

void CheckBitrate(const BusConfig& config, std::uint32_t bitrate) {
  if (bitrate != 0 && (bitrate < kMinBitrate || bitrate > kMaxBitrate))
    throw std::invalid_argument("bus " + config.name + ": port bit rate " + std::to_string(bitrate) +
                                " outside 10000..1000000 bit/s");
}

/// What a receiver sees of a failed transfer or of a frame at another bit rate: the frame's
/// identifier and format with kError set, DLC 0 (AttachOptions::error_frames).
CanFrame ErrorFrameOf(const CanFrame& frame) {
  CanFrame error_frame;
  error_frame.id = frame.id;
  error_frame.flags = static_cast<std::uint8_t>(CanFrame::kError | (frame.flags & CanFrame::kExtended));
  return error_frame;
}

/// What the wire carries: bytes beyond the DLC are not part of a frame (and a remote frame has
/// none), so they are cleared and captures of the same traffic are byte-identical.
CanFrame Normalized(const CanFrame& in) {
  CanFrame f = in;
  const std::size_t used = f.remote() ? 0 : f.dlc;
  std::fill(f.data.begin() + static_cast<std::ptrdiff_t>(used), f.data.end(), std::uint8_t{0});
  return f;
}

}  // namespace

template <class Change>
auto VirtualBus::WithRound(Change&& change) {
  if (in_round_) return change();
  in_round_ = true;
  // Catch up to now, but start no transfer at now before the change: a control action at an
  // instant applies before the arbitration at that instant (a port forced bus-off together with
  // a Submit sends nothing).
  Process(Now(), /*start_at_now=*/false);
  auto result = change();
  FlushAll();
  in_round_ = false;
  Sweep();
  Arm();
  return result;
}

VirtualBus::VirtualBus(Scheduler& scheduler, BusConfig config)
    : scheduler_(scheduler),
      config_(Validated(std::move(config))),
      created_(Now()),
      faults_(scheduler, rules_, *this),
      timer_(scheduler, [this] { OnTimer(); }),
      free_at_(created_),
      log_(LogCapacity(config_)) {
  delayed_.reserve(256);
  round_.frames_.reserve(256);
  round_.id_ = NextRoundId();
  timer_.Confine(Broker::kBusTimerKey);
}

void VirtualBus::Outlook(BusOutlook& out) const {
  out.calm = config_.paced && !rules_.MayCorrupt();
  out.next_event.reset();
  if (const auto next = NextEvent()) out.next_event = TimePoint(*next);
  out.frames.clear();
  out.transmitters = 0;
  std::size_t acknowledgers = 0;
  for (const auto& p : ports_) {
    if (p->detached) continue;
    const ControllerState state = p->controller.State();
    if (p->bitrate != config_.bitrate || state == ControllerState::kErrorPassive || p->recover_at ||
        p->babbling)
      out.calm = false;
    if (!p->options.listen_only) {
      ++out.transmitters;
      if (state != ControllerState::kBusOff) ++acknowledgers;
    }
    p->queue.ForEach([&](const QueuedFrame& q) { out.frames.push_back(q.frame); });
  }
  if (acknowledgers < 2) out.calm = false;  // a lone transmitter sees ACK errors
  if (in_flight_) out.frames.push_back(in_flight_->entry.frame);
  for (const Delayed& d : delayed_)
    out.frames.push_back(d.frame);
}

// ---------------------------------------------------------------------------------------------
// Ports

Port& VirtualBus::Attach(PortId id, std::string name, PortSink& sink, AttachOptions options) {
  CheckBitrate(config_, options.bitrate);
  auto port = std::make_unique<Port>(id, std::move(name), sink, options, Now(), config_.tx_queue_capacity);
  port->bitrate = options.bitrate != 0 ? options.bitrate : config_.bitrate;
  port->round_begin = static_cast<std::uint32_t>(round_.frames_.size());  // nothing from before it attached
  port->exceptions.reserve(64);
  port->tx.reserve(64);
  port->events.reserve(4);
  Port& ref = *port;
  ports_.push_back(std::move(port));
  Disturb();
  // A new port acknowledges: unpaced ports waiting after an ACK error may try again.
  for (auto& p : ports_)
    p->ack_blocked = false;
  if (!in_round_) Arm();
  return ref;
}

void VirtualBus::Detach(Port& port) {
  WithRound([&] {
    // A transfer of this port already on the wire completes (its receivers get it); nothing more
    // reaches the port. Its outbox is discarded by the flush.
    port.detached = true;
    port.sink = nullptr;
    Disturb();
    port.queue.clear();
    ++port.queue_epoch;
    if (port.recover_at) {
      port.recover_at.reset();
      --pending_recoveries_;
    }
    sweep_needed_ = true;
    return 0;
  });
}

std::size_t VirtualBus::Submit(Port& port, std::span<const CanFrame> frames) {
  const BusTime now = Now();
  std::size_t accepted = 0;
  for (const CanFrame& frame : frames) {
    if (!frame.valid() || frame.error() || port.options.listen_only || port.detached) {
      ++port.invalid_drops;
      continue;
    }
    // A bus-off controller takes no part in bus activity (ISO 11898-1:2015 §6.15).
    if (port.controller.State() == ControllerState::kBusOff) {
      ++port.bus_off_drops;
      continue;
    }
    if (!port.queue.push_back({Normalized(frame), now, next_seq_, false, false})) {
      ++port.queue_drops;
      ++queue_drops_;
      continue;
    }
    if (!config_.paced) order_.push_back({&port, next_seq_});
    ++next_seq_;
    ++accepted;
  }
  // Wake the bus. Not inside a round (it re-arms when it ends), not when the timer already fires
  // by now, and on a paced bus not while a transfer is on the wire (its end is armed and no frame
  // can start before it).
  if (accepted == 0 || in_round_) return accepted;
  if (timer_.Armed() && timer_.Deadline() <= TimePoint(now)) return accepted;
  if (!config_.paced)
    timer_.StartAt(TimePoint(now));
  else if (!in_flight_)
    Arm();
  return accepted;
}

bool VirtualBus::RecoverBusOff(Port& port) {
  return WithRound([&] {
    if (port.detached || port.controller.State() != ControllerState::kBusOff) return false;
    if (port.bus_off_cause) {
      ++port.failed_recoveries;  // the cause persists: the attempt fails
      return false;
    }
    Recover(port);
    return true;
  });
}

bool VirtualBus::ForceBusOff(Port& port, bool hold) {
  return WithRound([&] {
    if (port.detached) return false;
    if (port.controller.State() == ControllerState::kBusOff) {
      if (!hold || port.hold_bus_off) return false;
      // Already bus-off: the hold cancels the pending automatic recovery.
      port.hold_bus_off = true;
      if (port.recover_at) {
        port.recover_at.reset();
        --pending_recoveries_;
      }
      return true;
    }
    port.hold_bus_off = hold;
    Disturb();
    Emit(port, port.controller.ForceBusOff());
    EnterBusOff(port, Now());
    return true;
  });
}

bool VirtualBus::HoldBusOff(Port& port, bool on) {
  return WithRound([&] {
    if (port.detached || port.bus_off_cause == on) return false;
    port.bus_off_cause = on;
    // Released: the pending automatic attempt (if any) succeeds when it falls due.
    if (on && port.controller.State() != ControllerState::kBusOff) {
      Disturb();
      Emit(port, port.controller.ForceBusOff());
      EnterBusOff(port, Now());
    }
    return true;
  });
}

bool VirtualBus::HoldErrorPassive(Port& port, bool on) {
  return WithRound([&] {
    if (port.detached || port.controller.ErrorPassiveHeld() == on) return false;
    Disturb();
    Emit(port, port.controller.HoldErrorPassive(on));
    return true;
  });
}

bool VirtualBus::StartBabbling(Port& port, const CanFrame& frame) {
  if (!config_.paced)
    throw std::invalid_argument("bus " + config_.name +
                                " is unpaced: a babbling idiot needs the time line of a paced bus");
  if (!frame.valid() || frame.error())
    throw std::invalid_argument("babbling idiot: invalid frame " + ToCandump(frame));
  return WithRound([&] {
    if (port.detached || port.options.listen_only) return false;
    // Offered from now on, with a place in the submission order for ties in arbitration.
    port.babble = {Normalized(frame), Now(), next_seq_++, false, true};
    port.babbling = true;
    return true;
  });
}

bool VirtualBus::StopBabbling(Port& port) {
  return WithRound([&] {
    if (port.detached || !port.babbling) return false;
    port.babbling = false;
    return true;
  });
}

bool VirtualBus::SetBitrate(Port& port, std::uint32_t bitrate) {
  CheckBitrate(config_, bitrate);
  return WithRound([&] {
    if (port.detached) return false;
    // A transfer of the port already on the wire ends as it began; from now on the port takes
    // part at its new rate (the switch of CiA 305 §8.3.2 happens between frames).
    port.bitrate = bitrate != 0 ? bitrate : config_.bitrate;
    Disturb();
    // Who acknowledges whom changed: unpaced ports waiting after an ACK error may try again.
    for (auto& p : ports_)
      p->ack_blocked = false;
    return true;
  });
}

Port& VirtualBus::PortOnBus(PortId id) const {
  Port* port = Find(id);
  if (port == nullptr)
    throw std::invalid_argument("port " + std::to_string(id) + " is not on bus " + config_.name);
  return *port;
}

Port* VirtualBus::Find(PortId id) const {
  for (const auto& p : ports_)
    if (p->id == id && !p->detached) return p.get();
  return nullptr;
}

std::vector<const Port*> VirtualBus::Ports() const {
  std::vector<const Port*> out;
  for (const auto& p : ports_)
    if (!p->detached) out.push_back(p.get());
  return out;
}

// ---------------------------------------------------------------------------------------------
// Rounds

void VirtualBus::OnTimer() {
  Run();
}

void VirtualBus::Run() {
  // Inside a round (a sink drove the scheduler), the running round re-arms when it ends.
  if (in_round_) return;
  in_round_ = true;
  const BusTime now = Now();
  last_round_ = now;
  Process(now, /*start_at_now=*/true);
  FlushAll();
  in_round_ = false;
  Sweep();
  Arm();
}

bool VirtualBus::Eligible(const Port& port) const {
  return !port.detached && (!port.queue.empty() || port.babbling) &&
         port.controller.State() != ControllerState::kBusOff && (config_.paced || !port.ack_blocked);
}

Port* VirtualBus::OldestHead() const {
  while (!order_.empty()) {
    const SubmissionOrder::Entry entry = order_.front();
    const Port& port = *entry.port;
    // Stale: that frame left its queue (sent, or dropped at bus-off or detach).
    if (port.detached || port.queue.empty() || port.queue.front().seq != entry.seq) {
      order_.pop_front();
      continue;
    }
    if (Eligible(port)) return entry.port;
    // The oldest head waits for an acknowledger (a lone port after an ACK error); then nobody
    // else can send either, but a scan says so without relying on that.
    return ScanOldestHead();
  }
  return nullptr;
}

Port* VirtualBus::ScanOldestHead() const {
  Port* oldest = nullptr;
  for (const auto& p : ports_) {
    if (!Eligible(*p)) continue;
    if (oldest == nullptr || Head(*p).seq < Head(*oldest).seq) oldest = p.get();
  }
  return oldest;
}

std::optional<BusTime> VirtualBus::NextStart() const {
  if (!config_.paced) {
    const Port* oldest = OldestHead();
    if (oldest == nullptr) return std::nullopt;
    return Head(*oldest).submitted;
  }
  // A frame joins the first arbitration that starts at or after both its submission and the end
  // of its port's suspend-transmission time; the bus starts one as soon as it is idle and some
  // frame is ready ("a message pending during a transfer starts at the first bit after
  // intermission", ISO 11898-1:2015 §10.4 interframe space).
  std::optional<BusTime> earliest;
  for (const auto& p : ports_) {
    if (!Eligible(*p)) continue;
    const BusTime ready = std::max(Head(*p).submitted, p->ready_at);
    if (!earliest || ready < *earliest) earliest = ready;
  }
  if (!earliest) return std::nullopt;
  return std::max(*earliest, free_at_);
}

Port* VirtualBus::Arbitrate(BusTime start) const {
  // Every port offers the head of its FIFO queue (as a CAN driver with one TX buffer does);
  // the lowest arbitration key wins. Two ports sending the same identifier at once is a
  // configuration error on a real bus; here the earlier submission wins.
  Port* winner = nullptr;
  std::uint32_t best_key = 0;
  std::uint64_t best_seq = 0;
  for (const auto& p : ports_) {
    if (!Eligible(*p)) continue;
    const QueuedFrame& head = Head(*p);
    if (std::max(head.submitted, p->ready_at) > start) continue;
    const std::uint32_t key = ArbitrationKey(head.frame);
    if (winner == nullptr || key < best_key || (key == best_key && head.seq < best_seq)) {
      winner = p.get();
      best_key = key;
      best_seq = head.seq;
    }
  }
  return winner;
}

TransferOutcome VirtualBus::AckOutcome(const Port& transmitter, BusTime start) const {
  // Only a controller at the transmitter's rate samples the frame as sent and acknowledges it. To
  // one at another rate it is noise: it signals an error (README "Bit rate"), and when nobody
  // acknowledges, those error flags are what the transmitter sees (a bit error, not an ACK error).
  bool other_rate = false;
  for (const auto& p : ports_) {
    if (p.get() == &transmitter || p->detached || !AttachedBy(*p, start)) continue;
    if (!Acknowledges(p->controller.State(), p->options.listen_only)) continue;
    if (p->bitrate == transmitter.bitrate) return TransferOutcome::kOk;
    other_rate = true;
  }
  return other_rate ? TransferOutcome::kRateError : TransferOutcome::kAckError;
}

TransferOutcome VirtualBus::Outcome(Port& transmitter, const CanFrame& frame, BusTime start) {
  if (!rules_.Empty() && rules_.CorruptAttempt(transmitter.id, frame, start))
    return TransferOutcome::kCrcError;
  return AckOutcome(transmitter, start);
}

void VirtualBus::Process(BusTime now, bool start_at_now) {
  enum class Kind : std::uint8_t { kNone, kComplete, kRecover, kDelayed, kStart };
  for (;;) {
    // The earliest event; on equal times the order below: a transfer ends, then recoveries and
    // delayed deliveries happen, then the next arbitration starts.
    Kind kind = Kind::kNone;
    BusTime at{};
    auto consider = [&](BusTime t, Kind k) {
      if (kind == Kind::kNone || t < at) {
        kind = k;
        at = t;
      }
    };
    if (in_flight_) consider(in_flight_->end, Kind::kComplete);
    Port* recovering = nullptr;
    if (pending_recoveries_ > 0) {
      for (const auto& p : ports_)
        if (p->recover_at && (recovering == nullptr || *p->recover_at < *recovering->recover_at))
          recovering = p.get();
      if (recovering != nullptr) consider(*recovering->recover_at, Kind::kRecover);
    }
    if (!delayed_.empty()) consider(delayed_.front().due, Kind::kDelayed);
    std::optional<BusTime> start;
    Port* oldest = nullptr;  // unpaced: the next sender, found once per frame
    if (!in_flight_) {
      if (config_.paced) {
        start = NextStart();
      } else if ((oldest = OldestHead()) != nullptr) {
        start = Head(*oldest).submitted;
      }
      if (start) consider(*start, Kind::kStart);
    }
    if (kind == Kind::kNone || at > now) return;
    if (kind == Kind::kStart && at == now && !start_at_now) return;

    switch (kind) {
      case Kind::kComplete: {
        const InFlight transfer = *in_flight_;
        in_flight_.reset();
        Complete(transfer);
        break;
      }
      case Kind::kRecover:
        AttemptRecovery(*recovering);
        break;
      case Kind::kDelayed: {
        std::pop_heap(delayed_.begin(), delayed_.end(), DueLater);
        const Delayed delayed = delayed_.back();
        delayed_.pop_back();
        DeliverDelayed(delayed);
        break;
      }
      case Kind::kStart: {
        if (config_.paced) {
          Port* winner = Arbitrate(*start);
          const QueuedFrame& head = Head(*winner);
          const TransferOutcome outcome = Outcome(*winner, head.frame, *start);
          // The transmitter's bit rate sets the length (the bus's, unless the port runs at another).
          const BusTime end = *start + BitTime(AttemptBits(head.frame, outcome), winner->bitrate);
          in_flight_ = InFlight{winner, head, winner->queue_epoch, *start, end, outcome};
        } else {
          // No time line: the oldest submission goes, taking no time.
          Port* winner = oldest;
          const QueuedFrame head = Head(*winner);
          const TransferOutcome outcome = Outcome(*winner, head.frame, head.submitted);
          // A lone unpaced port would retry forever in zero time: it waits for another port.
          if (outcome == TransferOutcome::kAckError) winner->ack_blocked = true;
          Complete({winner, head, winner->queue_epoch, head.submitted, head.submitted, outcome});
        }
        break;
      }
      case Kind::kNone:
        return;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// A transfer ends

void VirtualBus::Complete(const InFlight& transfer) {
  if (config_.paced) free_at_ = transfer.end;
  const bool ok = transfer.outcome == TransferOutcome::kOk;
  log_.Record(transfer.start, transfer.end, transfer.entry.frame, !ok);
  if (ok)
    Delivered(transfer);
  else
    Failed(transfer);
}

void VirtualBus::Delivered(const InFlight& transfer) {
  Port& tx = *transfer.port;
  ++frames_;
  const bool faults = !rules_.Empty();
  const bool repeat = faults && rules_.EvaluateDelivery(tx.id, transfer.entry.frame, transfer.start,
                                                        transfer.entry.repetition);
  const TimedFrame timed{transfer.entry.frame, transfer.end};
  // Written once for every receiver (the shared round); a port that does not receive it skips
  // it. The sender never receives its own frame.
  const std::uint32_t index = ShareFrame(timed);
  tx.exceptions.push_back(index);
  if (!faults && ReceiversAtRest(tx, transfer.start))
    deliveries_ += ports_.size() - 1;  // every other port, nothing to count: no loop
  else
    deliveries_ += DeliverToEach(transfer, index, faults);
  if (faults) rules_.EndOfTransfer(transfer.start);
  if (TransmitterLive(transfer)) Confirm(transfer, timed, repeat);
}

std::uint64_t VirtualBus::DeliverToEach(const InFlight& transfer, std::uint32_t index, bool faults) {
  const Port& tx = *transfer.port;
  std::uint64_t delivered = 0;
  for (std::size_t i = 0; i < ports_.size(); ++i) {
    Port& rx = *ports_[i];
    if (&rx == &tx) continue;
    if (!Receives(rx, transfer.start)) {
      rx.exceptions.push_back(index);
      continue;
    }
    if (rx.bitrate != tx.bitrate) {
      SeeAtAnotherRate(rx, transfer, index);
      continue;
    }
    const FaultRules::Decision decision = faults ? rules_.ForReceiver(rx.id) : FaultRules::Decision{};
    switch (decision.kind) {
      case FaultRules::Decision::kDeliver:
        ++delivered;  // rx_frames: counted when the port is flushed
        break;
      case FaultRules::Decision::kDrop:
        rx.exceptions.push_back(index);
        ++rx.fault_drops;
        ++fault_drops_;
        break;
      case FaultRules::Decision::kDelay:
        rx.exceptions.push_back(index);
        delayed_.push_back({transfer.end + decision.delay, delay_seq_++, rx.id, transfer.entry.frame});
        std::push_heap(delayed_.begin(), delayed_.end(), DueLater);
        ++fault_delays_;
        break;
    }
    // Receiving a valid frame: REC − 1 (ISO 11898-1:2015 §12.1.4, rule 8). Usually nothing to
    // count (error-active, REC 0): tested first. (With every receiver so, and no fault rule,
    // this loop does not run at all: ReceiversAtRest.)
    if (!rx.options.listen_only && !rx.controller.ReceiveSuccessChangesNothing()) {
      Emit(rx, rx.controller.OnReceiveSuccess());
      Disturb();  // REC changed
    }
  }
  return delivered;
}

void VirtualBus::Confirm(const InFlight& transfer, const TimedFrame& timed, bool repeat) {
  Port& tx = *transfer.port;
  if (transfer.entry.babble) {
    // Not the node's frame: no confirmation, nothing leaves its queue.
    ++tx.babble_frames;
    tx.babble.repetition = repeat;
  } else {
    ++tx.tx_frames;
    if (!transfer.entry.repetition) tx.tx.push_back(timed);
    if (repeat)
      tx.queue.front().repetition = true;  // stays at the head: sent once more
    else
      tx.queue.pop_front();
  }
  // Successful transmission: TEC − 1 (rule 7).
  Emit(tx, tx.controller.OnTransmitSuccess());
  SuspendIfPassive(tx, transfer.end);
}

void VirtualBus::SeeAtAnotherRate(Port& rx, const InFlight& transfer, std::uint32_t index) {
  rx.exceptions.push_back(index);
  AddPrivateFrame(rx, {ErrorFrameOf(transfer.entry.frame), transfer.end});
  if (rx.options.listen_only) return;  // a monitor counts nothing
  ++rx.rx_errors;
  Emit(rx, rx.controller.OnReceiveError());
  Disturb();  // REC changed
}

void VirtualBus::Failed(const InFlight& transfer) {
  ++error_frames_;
  Disturb();  // counters change below
  const Port& tx = *transfer.port;
  const CanFrame error_frame = ErrorFrameOf(transfer.entry.frame);
  // Error frames go to the ports that asked for them, and to every port when the transfer failed
  // for a bit rate (the error flags of the ports at another rate) or was sent at another rate than
  // the port's own: those are what a node at the wrong rate, or its neighbours, see.
  const bool rate_error = transfer.outcome == TransferOutcome::kRateError;
  for (std::size_t i = 0; i < ports_.size(); ++i) {
    Port& p = *ports_[i];
    if (&p == &tx || !Receives(p, transfer.start)) continue;
    if (p.options.error_frames || rate_error || p.bitrate != tx.bitrate)
      AddPrivateFrame(p, {error_frame, transfer.end});
  }
  if (TransmitterLive(transfer)) CountTransmitError(transfer);
  if (transfer.outcome != TransferOutcome::kAckError) CountReceiveErrors(transfer);
}

void VirtualBus::CountTransmitError(const InFlight& transfer) {
  // Transmit error: TEC + 8 (rule 3), except an ACK error of an error-passive transmitter
  // (rule 3, exception 1): a lone node stops at error-passive. The frame stays queued and is
  // retransmitted automatically (ISO 11898-1:2015 §6.11).
  Port& tx = *transfer.port;
  ++tx.tx_errors;
  Emit(tx, tx.controller.OnTransmitError(TransmitErrorOf(transfer.outcome)));
  if (tx.controller.State() == ControllerState::kBusOff)
    EnterBusOff(tx, transfer.end);
  else
    SuspendIfPassive(tx, transfer.end);
}

void VirtualBus::CountReceiveErrors(const InFlight& transfer) {
  // Every receiver detects the error: REC + 1 (rule 1).
  for (std::size_t i = 0; i < ports_.size(); ++i) {
    Port& rx = *ports_[i];
    if (&rx == transfer.port || rx.options.listen_only || !Receives(rx, transfer.start)) continue;
    ++rx.rx_errors;
    Emit(rx, rx.controller.OnReceiveError());
  }
}

void VirtualBus::DeliverDelayed(const Delayed& delayed) {
  Port* rx = Find(delayed.receiver);
  if (rx == nullptr || rx->controller.State() == ControllerState::kBusOff) return;
  AddPrivateFrame(*rx, {delayed.frame, delayed.due});
  ++rx->rx_frames;
  ++deliveries_;
}

void VirtualBus::AttemptRecovery(Port& port) {
  if (port.bus_off_cause) {
    // The cause persists: the controller does not see its 128 × 11 recessive bits, stays bus-off
    // and starts counting again.
    ++port.failed_recoveries;
    port.recover_at = RecoveryAttemptAt(*port.recover_at, port.bitrate);
    return;
  }
  Recover(port);
}

void VirtualBus::Recover(Port& port) {
  if (port.recover_at) {
    port.recover_at.reset();
    --pending_recoveries_;
  }
  port.hold_bus_off = false;
  Disturb();
  Emit(port, port.controller.Recover());
  // The recovered controller acknowledges again: unpaced ports waiting after an ACK error may
  // try again (as when a port attaches).
  for (auto& p : ports_)
    p->ack_blocked = false;
}

void VirtualBus::EnterBusOff(Port& port, BusTime at) {
  Disturb();
  // A bus-off node's pending frames are not sent: the queue is dropped (counted).
  port.bus_off_drops += port.queue.size();
  port.queue.clear();
  ++port.queue_epoch;
  port.ready_at = BusTime{};
  if (config_.auto_recover && !port.hold_bus_off && !port.recover_at) {
    port.recover_at = RecoveryAttemptAt(at, port.bitrate);
    ++pending_recoveries_;
  }
}

void VirtualBus::SuspendIfPassive(Port& port, BusTime end) {
  if (config_.paced && port.controller.State() == ControllerState::kErrorPassive)
    port.ready_at = ReadyAfterTransfer(ControllerState::kErrorPassive, end, port.bitrate);
}

void VirtualBus::Emit(Port& port, const std::optional<ControllerEvent>& event) {
  if (!event) return;
  port.events.push_back({round_.frames_.size(), port.tx.size(), *event});
  Disturb();  // the port's state changed
}

bool VirtualBus::ReceiversAtRest(const Port& tx, BusTime start) {
  if (!rest_.valid) {
    rest_ = RestSummary{.valid = true};
    for (const auto& p : ports_) {
      rest_.newest_attach = std::max(rest_.newest_attach, p->attached_at);
      const bool at_rest = !p->detached && p->controller.State() != ControllerState::kBusOff &&
                           p->bitrate == config_.bitrate &&
                           (p->options.listen_only || p->controller.ReceiveSuccessChangesNothing());
      if (!at_rest) {
        ++rest_.busy;
        rest_.busy_port = p.get();
      }
    }
  }
  if (config_.paced && rest_.newest_attach > start) return false;
  return rest_.busy == 0 || (rest_.busy == 1 && rest_.busy_port == &tx);
}

// ---------------------------------------------------------------------------------------------
// Timer and delivery

std::optional<BusTime> VirtualBus::NextEvent() const {
  std::optional<BusTime> next;
  auto consider = [&](BusTime t) {
    if (!next || t < *next) next = t;
  };
  if (in_flight_) {
    consider(in_flight_->end);
  } else if (auto start = NextStart()) {
    // Unpaced: frames submitted during a round go in a round at least 1 ns later on the
    // scheduler's time line, so two sinks answering each other cannot spin forever at one
    // instant of simulated time (real time: the next turn of the event loop).
    if (!config_.paced && last_round_) start = std::max(*start, *last_round_ + BusTime(1));
    consider(*start);
  }
  if (!delayed_.empty()) consider(delayed_.front().due);
  if (pending_recoveries_ > 0)
    for (const auto& p : ports_)
      if (p->recover_at) consider(*p->recover_at);
  return next;
}

void VirtualBus::Arm() {
  const auto next = NextEvent();
  if (!next) {
    timer_.Cancel();
    return;
  }
  const TimePoint at(*next);
  if (!timer_.Armed() || timer_.Deadline() != at) timer_.StartAt(at);
}

void VirtualBus::FlushAll() {
  // Sinks may cause new controller events (a forced bus-off from inside a callback) or attach
  // ports: repeat until every outbox is empty. Index loops: ports_ may grow meanwhile.
  bool again = true;
  while (again) {
    again = false;
    for (std::size_t i = 0; i < ports_.size(); ++i) {
      Port& port = *ports_[i];
      if (!HasOutbox(port)) continue;
      FlushPort(port);
      again = true;
    }
  }
  ResetRound();
}

void VirtualBus::ResetRound() {
  if (round_.frames_.empty()) return;
  round_.frames_.clear();
  round_.id_ = NextRoundId();
  private_.clear();
  for (auto& p : ports_)
    p->round_begin = 0;
}

void VirtualBus::FlushPort(Port& port) {
  // The shared round and tx do not change while sinks run (nothing is processed inside a round's
  // flush), so the spans stay valid; events may be appended (the loop re-reads the size).
  const std::span<const std::uint32_t> exceptions = port.exceptions.items();
  std::size_t next_exception = 0;
  auto next_private = std::lower_bound(private_.begin(), private_.end(), port.round_begin);
  std::uint32_t rx_done = port.round_begin;
  std::size_t tx_done = 0;
  // The port's share of round_ [rx_done, rx_mark) as runs: cut at its own exceptions (skipped
  // frames) and at frames addressed to other ports alone.
  auto deliver_up_to = [&](std::uint32_t rx_mark) {
    constexpr std::uint32_t kNone = ~std::uint32_t{0};
    runs_.clear();
    std::uint32_t run_begin = rx_done;
    std::uint32_t included = 0;
    for (;;) {
      const std::uint32_t exception = next_exception < exceptions.size() ? exceptions[next_exception] : kNone;
      const std::uint32_t exception_at = exception == kNone ? kNone : exception & ~Port::kInclude;
      const std::uint32_t private_at = next_private != private_.end() ? *next_private : kNone;
      const std::uint32_t at = std::min(exception_at, private_at);
      if (at >= rx_mark) break;
      bool cut = true;
      if (exception_at == at) {
        ++next_exception;
        if ((exception & Port::kInclude) != 0) {
          cut = false;  // addressed to this port: part of its run
          ++included;
        }
      }
      if (private_at == at) ++next_private;
      if (cut) {
        if (at > run_begin) runs_.push_back({run_begin, at});
        run_begin = at + 1;
      }
    }
    if (rx_mark > run_begin) runs_.push_back({run_begin, rx_mark});
    rx_done = rx_mark;
    if (runs_.empty()) return;
    std::uint64_t received = 0;
    for (const FrameRun& run : runs_)
      received += run.size();
    // Private frames were counted when added (delayed) or are not counted (error frames).
    port.rx_frames += received - included;
    if (port.sink != nullptr) port.sink->DeliverShared(round_, runs_);
  };
  auto frames_up_to = [&](std::size_t rx_mark, std::size_t tx_mark) {
    if (rx_mark > rx_done) deliver_up_to(static_cast<std::uint32_t>(rx_mark));
    if (tx_mark > tx_done) {
      if (port.sink != nullptr) port.sink->TxConfirmed(port.tx.items().subspan(tx_done, tx_mark - tx_done));
      tx_done = tx_mark;
    }
  };
  for (std::size_t e = 0; e < port.events.size(); ++e) {
    const Port::PendingEvent pending = port.events[e];
    frames_up_to(pending.rx_mark, pending.tx_mark);
    if (port.sink != nullptr) port.sink->ControllerChanged(pending.event);
  }
  frames_up_to(round_.frames_.size(), port.tx.size());
  port.round_begin = static_cast<std::uint32_t>(round_.frames_.size());
  port.exceptions.clear();
  port.tx.clear();
  port.events.clear();
}

void VirtualBus::Sweep() {
  if (!sweep_needed_) return;
  const Port* on_wire = in_flight_ ? in_flight_->port : nullptr;
  // No entry may outlive its port (a detached port's entries are stale anyway).
  order_.EraseIf(
      [on_wire](const SubmissionOrder::Entry& e) { return e.port->detached && e.port != on_wire; });
  std::erase_if(ports_,
                [on_wire](const std::unique_ptr<Port>& p) { return p->detached && p.get() != on_wire; });
  Disturb();
  sweep_needed_ = on_wire != nullptr && on_wire->detached;
}

// ---------------------------------------------------------------------------------------------
// Statistics

BusStats VirtualBus::Stats(std::size_t top_ids) const {
  BusStats s;
  s.name = config_.name;
  s.bitrate = config_.bitrate;
  s.paced = config_.paced;
  s.ports = Ports().size();
  s.time = Now();
  std::optional<TransmissionLog::Ongoing> ongoing;
  if (in_flight_) ongoing = TransmissionLog::Ongoing{in_flight_->start, in_flight_->end};
  log_.Summarize(s.time, config_.stats_window, created_, ongoing, top_ids, s);
  if (!config_.paced) s.load_percent = 0;
  s.frames = frames_;
  s.error_frames = error_frames_;
  s.deliveries = deliveries_;
  s.queue_drops = queue_drops_;
  s.fault_drops = fault_drops_;
  s.fault_delays = fault_delays_;
  return s;
}

PortStats VirtualBus::StatsOf(const Port& port) const {
  PortStats s;
  s.id = port.id;
  s.bus = config_.name;
  s.name = port.name;
  s.controller = port.controller.Snapshot();
  s.bitrate = port.bitrate;
  s.queued = port.queue.size();
  s.tx_frames = port.tx_frames;
  s.rx_frames = port.rx_frames;
  s.tx_errors = port.tx_errors;
  s.rx_errors = port.rx_errors;
  s.queue_drops = port.queue_drops;
  s.invalid_drops = port.invalid_drops;
  s.bus_off_drops = port.bus_off_drops;
  s.fault_drops = port.fault_drops;
  s.babble_frames = port.babble_frames;
  s.failed_recoveries = port.failed_recoveries;
  return s;
}

}  // namespace canfleet::broker::detail
