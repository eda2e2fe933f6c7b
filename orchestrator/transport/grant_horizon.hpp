#pragma once
/// @file Per-node lookahead of lock-step virtual time (issue 34, orchestrator/broker/README.md
/// "Virtual time"): how far each node process may be granted, as the earliest time anything could
/// reach it. Pure computation: TimeConductor gathers what it knows and grants from the result.
///
/// What reaches a node process on a port:
/// - frames already on the bus (in flight, queued, delayed by a fault) that it listens to: from the
///   bus's next event on;
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
/// the time stamps of a process's messages, with the acceptance filters as its links).

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
  bool operator==(const ConfinedSend&) const = default;
};

struct HorizonBus {
  /// No transfer can fail and no controller change state by itself; only node processes transmit.
  bool calm = false;
  std::optional<TimePoint> next_event;
  /// Acceptance keys of the frames on the bus (Acceptance::KeyOf), in any order.
  std::vector<std::uint32_t> pending_keys;
  bool boot_up = false;  ///< one of them is a boot-up (CiA 301: 700h + node-ID, one byte 00h)
};

struct HorizonPort {
  std::size_t bus = 0;  ///< index into the buses
  /// What it hears of what the others send from unconfined timers or on input.
  const Acceptance* acceptance = nullptr;
  /// What it hears of what their confined timers send, and of the frames on the bus; nullptr: as
  /// `acceptance`. A master that configures a node when it boots up hears boot-ups, which a
  /// heartbeat producer's timer never sends.
  const Acceptance* confined = nullptr;
  bool boot_ups = false;  ///< frames on the bus reach it when one is a boot-up
  const Acceptance& Confined() const { return confined != nullptr ? *confined : *acceptance; }
};

struct HorizonNode {
  bool pending = false;           ///< something reached it at `now`
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
  void Compute(TimePoint now, Duration lookahead, std::optional<TimePoint> cap,
               std::span<const HorizonBus> buses, std::span<const HorizonNode> nodes);
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
  struct Confined {
    std::size_t bus;
    std::uint32_t id;
    TimePoint time;
    std::size_t owner;
  };
  /// The earliest time `node` hears a confined identifier from another process on `bus`
  /// (`acceptance`: HorizonPort::Confined).
  TimePoint ConfinedBound(std::size_t node, std::size_t bus, const Acceptance& acceptance) const;

  std::vector<TimePoint> own_;     ///< earliest time each may send anything by itself
  std::vector<TimePoint> active_;  ///< its earliest timer at all
  std::vector<TimePoint> sends_;   ///< earliest time it may send anything (own_ or on input)
  std::vector<TimePoint> fixed_;  ///< per node: the part of its horizon that does not move in the fixed point
  std::vector<TimePoint> horizon_;
  std::vector<Best2> any_;          ///< per bus: over its nodes, sends_
  std::vector<Best2> all_;          ///< per bus: over its nodes, min(active_, sends_)
  std::vector<Confined> confined_;  ///< sorted by (bus, id, time)
  std::size_t passes_ = 0;
};

}  // namespace canfleet::transport
