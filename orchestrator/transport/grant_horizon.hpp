#pragma once
/// @file Per-node lookahead of lock-step virtual time (issue 34, orchestrator/broker/README.md
/// "Virtual time"): how far each node process may be granted, as the earliest time anything could
/// reach it. Pure computation: TimeConductor gathers what it knows and grants from the result.
///
/// What reaches a node process on a port:
/// - frames already on the bus (in flight, queued, delayed by a fault), or sent ahead of it, that it
///   listens to: from the bus's next event on, or from their stamps plus the lookahead;
/// - frames the other processes will send that it listens to: from the earliest time the sender
///   may send that identifier, plus the lookahead (no frame ends sooner after its submission).
///   A sender may send an identifier from its earliest timer that is not confined to other
///   identifiers (Timer::Confine: a heartbeat producer sends only its heartbeat, a TPDO's event
///   timer only its TPDO), or as soon as something reaches it (it may answer anything);
/// - on a bus that is not calm (a transfer may fail, a controller may change state, a port that
///   is not a node process may transmit): anything any process on it sends, its own frames
///   included (an error frame, a controller event), from that process's earliest timer on;
/// - whatever the broker does on its own (a scenario step, a fault's timer, an outside input):
///   `cap`, the same for every process.
/// The earliest time a process may send anything depends on the earliest time something reaches
/// it, so the two are computed together, to a fixed point (Chandy-Misra-Bryant's lower bounds on
/// the time stamps of a process's messages, with the acceptance filters as its links). A heartbeat
/// on a passive identifier (a consumer that only re-arms its timeout) makes it send nothing before
/// the identifier's delay: a ring of heartbeat consumers does not hold every node to the ring's
/// earliest heartbeat.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "clock/scheduler.hpp"
#include "orchestrator/transport/acceptance.hpp"

namespace canfleet::transport {

/// A node process's timers may send `id` (11-bit) from `time` on.
struct ConfinedSend {
  std::uint32_t id = 0;
  TimePoint time{};
  /// A heartbeat producer's: one state byte, never a boot-up (Acceptance::Passive applies).
  bool heartbeat = false;
  bool operator==(const ConfinedSend&) const = default;
};

/// A frame a process sent, stamped `time`, that is not on the bus yet (the process ran ahead).
struct KnownFrame {
  std::size_t bus = 0;
  std::size_t owner = 0;  ///< index of the node that sent it
  std::uint32_t key = 0;  ///< Acceptance::KeyOf
  TimePoint time{};
  bool heartbeat = false;  ///< IsHeartbeat
};

/// A heartbeat (CiA 301 §7.2.8.3.2.2: 701h..77Fh, one state byte), not a boot-up (state 00h): what
/// a passive identifier (Acceptance::Passive) answers only after its delay.
inline bool IsHeartbeat(const CanFrame& f) {
  return !f.extended() && !f.remote() && !f.error() && f.id > 0x700 && f.id <= 0x77F && f.dlc == 1 &&
         (f.data[0] & 0x7F) != 0;
}

/// A frame on a bus (in flight, queued, delayed by a fault).
struct PendingFrame {
  std::uint32_t key = 0;  ///< Acceptance::KeyOf
  bool heartbeat = false;
};

struct HorizonBus {
  /// No transfer can fail and no controller change state by itself; only node processes (and
  /// reactors, which count as such) transmit.
  bool calm = false;
  std::optional<TimePoint> next_event;
  std::vector<PendingFrame> pending;  ///< each reaches its listeners at next_event or later
};

struct HorizonPort {
  std::size_t bus = 0;  ///< index into the buses
  const Acceptance* acceptance = nullptr;
};

struct HorizonNode {
  bool pending = false;           ///< something reached it at `now`
  Duration reacts_after{};        ///< pending: it sends nothing on what reached it before now + this
  std::optional<TimePoint> next;  ///< its earliest timer
  /// Its earliest timer that may send any identifier (not confined); as `next` when it said nothing.
  std::optional<TimePoint> any;
  std::span<const ConfinedSend> confined;  ///< its confined timers' earliest times, per identifier
  std::span<const HorizonPort> ports;
};

class GrantHorizons {
 public:
  /// Computes, for each node, the earliest time anything can reach it after `now` (nullopt:
  /// nothing can), at most `cap`. `lookahead`: the shortest time from a frame's submission to
  /// anything a receiver sees of it.
  /// `known`: frames sent ahead of the bus.
  void Compute(TimePoint now, Duration lookahead, std::optional<TimePoint> cap,
               std::span<const HorizonBus> buses, std::span<const HorizonNode> nodes,
               std::span<const KnownFrame> known = {});
  std::optional<TimePoint> Of(std::size_t node) const {
    return horizon_[node] == kNever ? std::nullopt : std::optional(horizon_[node]);
  }
  /// Passes of the fixed point in the last Compute (statistics).
  std::size_t Passes() const { return passes_; }

 private:
  static constexpr TimePoint kNever = TimePoint::max();
  /// The two earliest times of a set and the owner of the earliest, so that a node can take the
  /// earliest of the others.
  struct Best2 {
    TimePoint first = kNever, second = kNever;
    std::size_t owner = SIZE_MAX;
    void Add(TimePoint t, std::size_t who);
    TimePoint Except(std::size_t who) const { return who == owner ? second : first; }
  };
  /// The earliest time `node` hears a confined identifier (or a known frame) from another process
  /// on `bus`, and the earliest time that may make it send.
  std::pair<TimePoint, TimePoint> ConfinedBound(std::size_t node, std::size_t bus,
                                                const Acceptance& acceptance) const;

  std::vector<TimePoint> own_;     ///< earliest time each may send anything by itself
  std::vector<TimePoint> active_;  ///< its earliest timer at all
  std::vector<TimePoint> sends_;   ///< earliest time it may send anything (own_ or on input)
  std::vector<TimePoint> fixed_;  ///< per node: the part of its horizon that does not move in the fixed point
  std::vector<TimePoint> fixed_react_;  ///< the same for what may make it send (passive frames later)
  std::vector<TimePoint> horizon_;
  std::vector<Best2> any_;                   ///< per bus: over its nodes, sends_
  std::vector<Best2> all_;                   ///< per bus: over its nodes, min(active_, sends_)
  static constexpr std::size_t kIds = 2048;  ///< 11-bit identifiers
  /// Per bus and identifier, the two earliest confined times and the owner of the earliest: of
  /// heartbeats (beats_, which a passive identifier answers only after its delay), of the rest.
  std::vector<Best2> table_, beats_;
  std::vector<std::size_t> touched_;  ///< entries of table_ and beats_ set in this Compute
  std::vector<TimePoint> anybody_;    ///< per bus: the earliest known frame that may reach anybody
  std::vector<Best2> noted_;          ///< per bus: over every Note (what an accept-all port hears)
  void Note(std::size_t bus, std::uint32_t id, TimePoint time, std::size_t owner, bool heartbeat);
  std::size_t passes_ = 0;
};

}  // namespace canfleet::transport
