#pragma once
/// @file One virtual bus: the ports on it, arbitration, the time line, error confinement, the
/// fault stage and delivery. Internal to the broker (Broker is the public face).
///
/// The bus is a discrete-event simulation driven by one Timer. Every event has a bus time:
/// end of a transfer, start of the next arbitration, a delayed delivery falling due, a bus-off
/// recovery. When the timer fires (on time in simulated time, late in real time), the bus
/// processes every event whose time is ≤ now in time order, back to back, then hands each port
/// one batch. Because every decision is taken from bus times (a frame joins an arbitration only if
/// it was submitted by its start), batching never changes the order or the timestamps.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "bus/physics/fault_confinement.hpp"
#include "bus/physics/wire_model.hpp"
#include "clock/scheduler.hpp"
#include "orchestrator/broker/broker.hpp"
#include "orchestrator/broker/bus_config.hpp"
#include "orchestrator/broker/fault_rules.hpp"
#include "orchestrator/broker/fault_stage.hpp"
#include "orchestrator/broker/outbox.hpp"
#include "orchestrator/broker/port_sink.hpp"
#include "orchestrator/broker/stats.hpp"
#include "orchestrator/broker/submission_order.hpp"
#include "orchestrator/broker/transmission_log.hpp"
#include "orchestrator/broker/tx_queue.hpp"

namespace canfleet::broker::detail {

struct Port {
  Port(PortId port_id, std::string port_name, PortSink& port_sink, AttachOptions port_options,
       BusTime attached, std::size_t queue_capacity)
      : id(port_id),
        name(std::move(port_name)),
        sink(&port_sink),
        options(port_options),
        attached_at(attached),
        queue(queue_capacity) {}

  PortId id;
  std::string name;
  PortSink* sink;  ///< nullptr once detached
  AttachOptions options;
  /// The rate its controller runs at (bit/s): AttachOptions::bitrate, or the bus's. A transfer
  /// reaches only the ports at its transmitter's rate (VirtualBus::SetBitrate).
  std::uint32_t bitrate = 0;
  BusTime attached_at;  ///< transfers that started before this are not received
  bool detached = false;

  TxQueue queue;
  std::uint32_t queue_epoch = 0;  ///< bumped whenever the queue is dropped (bus-off, detach)
  FaultConfinement controller;
  BusTime ready_at{};                 ///< suspend transmission: may not start a transfer before
  std::optional<BusTime> recover_at;  ///< automatic bus-off recovery due
  bool hold_bus_off = false;          ///< bus-off until RecoverBusOff (FaultStage::ForceBusOff hold)
  bool bus_off_cause = false;         ///< every recovery attempt fails (FaultStage::HoldBusOff)
  bool ack_blocked = false;           ///< unpaced: head got an ACK error, wait for another port
  /// Babbling idiot (FaultStage::StartBabbling): this entry is offered ahead of the queue.
  bool babbling = false;
  QueuedFrame babble{};

  // What the current round has for this port, in bus order. Received frames are not copied per
  // port: the port receives the bus's shared round from `round_begin` on, except its own frames
  // and `exceptions` (VirtualBus::SkipFrame, IncludeFrame).
  struct PendingEvent {
    std::size_t rx_mark;  ///< shared-round frames (received or not) that precede the event
    std::size_t tx_mark;
    ControllerEvent event;
  };
  std::uint32_t round_begin = 0;  ///< first shared-round frame not yet flushed to this port
  /// Ascending shared-round indexes: a frame of the round this port does not receive, or, with
  /// kInclude, a frame addressed to it alone.
  AppendBuffer<std::uint32_t> exceptions;
  static constexpr std::uint32_t kInclude = std::uint32_t{1} << 31;
  Outbox tx;
  std::vector<PendingEvent> events;

  std::uint64_t tx_frames = 0, rx_frames = 0, tx_errors = 0, rx_errors = 0;
  std::uint64_t queue_drops = 0, invalid_drops = 0, bus_off_drops = 0, fault_drops = 0;
  std::uint64_t babble_frames = 0;
  std::uint64_t failed_recoveries = 0;
};

class VirtualBus {
 public:
  /// Throws std::invalid_argument on a bitrate outside 10k..1M, an empty queue or window.
  VirtualBus(Scheduler& scheduler, BusConfig config);
  VirtualBus(const VirtualBus&) = delete;
  VirtualBus& operator=(const VirtualBus&) = delete;

  const BusConfig& Config() const { return config_; }

  Port& Attach(PortId id, std::string name, PortSink& sink, AttachOptions options);
  void Detach(Port& port);
  std::size_t Submit(Port& port, std::span<const CanFrame> frames);
  bool RecoverBusOff(Port& port);
  // Direct controller faults (FaultStage's public face documents them).
  bool ForceBusOff(Port& port, bool hold);
  bool HoldBusOff(Port& port, bool on);
  bool HoldErrorPassive(Port& port, bool on);
  bool StartBabbling(Port& port, const CanFrame& frame);
  bool StopBabbling(Port& port);
  /// The port's controller now runs at `bitrate` (0 = the bus's rate). Throws
  /// std::invalid_argument outside 10 000..1 000 000.
  bool SetBitrate(Port& port, std::uint32_t bitrate);
  /// The attached port `id`; throws std::invalid_argument when it is not on this bus.
  Port& PortOnBus(PortId id) const;

  FaultStage& Faults() { return faults_; }
  void Outlook(BusOutlook& out) const;
  BusStats Stats(std::size_t top_ids) const;
  PortStats StatsOf(const Port& port) const;
  /// The attached ports, in attach order.
  std::vector<const Port*> Ports() const;

 private:
  struct InFlight {
    Port* port;
    QueuedFrame entry;
    std::uint32_t epoch;
    BusTime start;
    BusTime end;
    TransferOutcome outcome;
  };
  struct Delayed {
    BusTime due;
    std::uint64_t seq;
    PortId receiver;
    CanFrame frame;
  };
  /// Heap order of delayed deliveries: earliest due first, then in the order they were delayed.
  static bool DueLater(const Delayed& a, const Delayed& b) {
    return a.due != b.due ? a.due > b.due : a.seq > b.seq;
  }

  BusTime Now() const { return scheduler_.Now().time_since_epoch(); }

  void OnTimer();
  /// Processes, flushes, sweeps and re-arms, unless a round is already running.
  void Run();
  /// Runs `change` inside a round at Now(): the bus first catches up to Now(), the outboxes are
  /// flushed after. Nested calls (from a sink) just run `change`; the running round flushes.
  template <class Change>
  auto WithRound(Change&& change);

  /// Handles every event due by `now` in time order. `start_at_now`: whether a transfer may
  /// start at `now` itself (false while catching up before a control action).
  void Process(BusTime now, bool start_at_now);
  bool Eligible(const Port& port) const;
  /// What the port offers for arbitration: its babble frame while babbling, else its queue's head.
  /// Only for an eligible port.
  static const QueuedFrame& Head(const Port& port) {
    return port.babbling ? port.babble : port.queue.front();
  }
  std::optional<BusTime> NextStart() const;
  Port* Arbitrate(BusTime start) const;
  /// Unpaced: the eligible port whose head was submitted first (O(1), see SubmissionOrder).
  Port* OldestHead() const;
  /// The same by a scan of the ports: when the oldest head's port is waiting for an acknowledger.
  Port* ScanOldestHead() const;
  /// Whether `port` was on the bus when a transfer started at `start` (a port that attaches
  /// mid-frame missed its start of frame). Unpaced buses have no time line: every attached port.
  bool AttachedBy(const Port& port, BusTime start) const {
    return !config_.paced || port.attached_at <= start;
  }
  /// How a transfer of `transmitter` that started at `start` ends if no fault rule corrupts it:
  /// acknowledged by a port at its rate (kOk); else destroyed by the error flags of a port at
  /// another rate (kRateError); else nobody drives the bus but the transmitter (kAckError).
  TransferOutcome AckOutcome(const Port& transmitter, BusTime start) const;
  /// Whether `port` takes part in a transfer that started at `start` as a receiver.
  bool Receives(const Port& port, BusTime start) const {
    return !port.detached && AttachedBy(port, start) && port.controller.State() != ControllerState::kBusOff;
  }
  /// The transmitter may have been detached or forced bus-off while its frame was on the wire: the
  /// frame still completes for the receivers, but the transmitter's side is gone.
  static bool TransmitterLive(const InFlight& transfer) {
    const Port& tx = *transfer.port;
    return !tx.detached && tx.queue_epoch == transfer.epoch &&
           tx.controller.State() != ControllerState::kBusOff;
  }
  TransferOutcome Outcome(Port& transmitter, const CanFrame& frame, BusTime start);

  // ---- A transfer ends: one function per outcome, the wire's rules from bus/physics/ ----
  void Complete(const InFlight& transfer);
  /// Acknowledged: shared with every receiver, each as the fault rules decide; TX confirmation.
  void Delivered(const InFlight& transfer);
  /// Serves each receiver by the fault rules' decision for it and counts its REC; returns how many
  /// got the frame now.
  std::uint64_t DeliverToEach(const InFlight& transfer, std::uint32_t index, bool faults);
  /// The transmitter's side of an acknowledged transfer: its own frame leaves the queue (or stays
  /// for a repetition), a babble frame does not; TEC − 1.
  void Confirm(const InFlight& transfer, const TimedFrame& timed, bool repeat);
  /// Failed (ACK or CRC error): error frames to the ports that want them, the counters' rules.
  void Failed(const InFlight& transfer);
  void CountTransmitError(const InFlight& transfer);
  /// A receiver at another rate than the transmitter: instead of the frame it sees an error frame
  /// and counts a receive error (ISO 11898-1:2015 §12.1.4.2 rule 1). `index`: the frame's place in
  /// the shared round, which `rx` skips.
  void SeeAtAnotherRate(Port& rx, const InFlight& transfer, std::uint32_t index);
  void CountReceiveErrors(const InFlight& transfer);

  void DeliverDelayed(const Delayed& delayed);
  /// An automatic recovery attempt falls due: it fails while a cause holds the port bus-off.
  void AttemptRecovery(Port& port);
  void Recover(Port& port);
  void EnterBusOff(Port& port, BusTime at);
  void SuspendIfPassive(Port& port, BusTime end);
  void Emit(Port& port, const std::optional<ControllerEvent>& event);
  /// Appends a frame to the shared round (every port receives it unless it skips it); returns its
  /// index.
  std::uint32_t ShareFrame(const TimedFrame& frame) {
    const auto index = static_cast<std::uint32_t>(round_.frames_.size());
    round_.frames_.push_back(frame);
    return index;
  }
  /// Appends a frame to the shared round for `port` alone (a delayed frame, an error frame).
  void AddPrivateFrame(Port& port, const TimedFrame& frame) {
    const std::uint32_t index = ShareFrame(frame);
    private_.push_back(index);
    port.exceptions.push_back(index | Port::kInclude);
  }
  bool HasOutbox(const Port& port) const {
    return port.round_begin < round_.frames_.size() || !port.tx.empty() || !port.events.empty();
  }
  /// Ends the round's sharing: every port has been flushed.
  void ResetRound();
  /// Whether a frame sent by `tx` that started at `start` needs no work per receiver: no port
  /// other than `tx` is detached, bus-off, counting REC down, at another bit rate than the bus or
  /// (paced) attached after `start`.
  /// Then every other port receives it and nothing else changes (the fast path of Delivered).
  bool ReceiversAtRest(const Port& tx, BusTime start);
  /// Something ReceiversAtRest depends on may have changed.
  void Disturb() { rest_.valid = false; }
  std::optional<BusTime> NextEvent() const;
  void Arm();
  void FlushAll();
  void FlushPort(Port& port);
  void Sweep();
  Port* Find(PortId id) const;

  Scheduler& scheduler_;
  BusConfig config_;
  BusTime created_;
  FaultRules rules_;   ///< decides
  FaultStage faults_;  ///< the public face of rules_ and of the controller faults
  Timer timer_;

  std::vector<std::unique_ptr<Port>> ports_;
  /// Unpaced buses: every accepted frame in submission order. Mutable: OldestHead discards stale
  /// entries as it finds them, which changes no observable state.
  mutable SubmissionOrder order_;
  std::optional<InFlight> in_flight_;
  BusTime free_at_{};  ///< end of the last transfer (intermission included): the bus is idle from then
  std::vector<Delayed> delayed_;  ///< min-heap on (due, seq)
  std::size_t pending_recoveries_ = 0;
  std::uint64_t next_seq_ = 0;
  std::uint64_t delay_seq_ = 0;
  std::optional<BusTime> last_round_;  ///< when the timer last ran a round
  bool in_round_ = false;
  bool sweep_needed_ = false;

  SharedRound round_;  ///< the frames of the current round, shared by every port
  /// Ascending indexes of round_ frames addressed to one port only (AddPrivateFrame).
  std::vector<std::uint32_t> private_;
  std::vector<FrameRun> runs_;  ///< FlushPort's scratch
  /// ReceiversAtRest's summary of the ports, recomputed after Disturb.
  struct RestSummary {
    bool valid = false;
    std::size_t busy = 0;             ///< ports not at rest
    const Port* busy_port = nullptr;  ///< one of them
    BusTime newest_attach{};          ///< latest attached_at
  } rest_;

  TransmissionLog log_;
  std::uint64_t frames_ = 0, error_frames_ = 0, deliveries_ = 0;
  std::uint64_t queue_drops_ = 0, fault_drops_ = 0, fault_delays_ = 0;
};

}  // namespace canfleet::broker::detail
