#pragma once
/// @file The judgement of one expectation of a scenario (issue 21), kept pure: it is told when its
/// window opens and closes, and fed what the fleet shows (frames on the buses, polled samples);
/// it decides pass or fail and says what it saw. No clock, no I/O: the scenario runner
/// (scenario_runner.hpp) times windows on the orchestrator's scheduler, so real and (later)
/// virtual time drive the same judges, and unit tests drive them by hand.
///
/// Windows include both ends: an observation at exactly open or close counts; one before open or
/// after close is ignored.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bus/can_frame.hpp"
#include "clock/scheduler.hpp"
#include "orchestrator/topology/canfleet_topology.pb.h"

namespace canfleet::scenario {

enum class Outcome { kPending, kPassed, kFailed, kSkipped };

/// "pass", "FAIL", "skip", "pending".
const char* OutcomeName(Outcome outcome);

struct Verdict {
  Outcome outcome = Outcome::kPending;
  /// When it was decided. For a pass on something seen, the time it was seen (expectations timed
  /// after this one count from there).
  TimePoint time{};
  /// Pass: what was seen. Fail: what was seen instead. Skip: why it was not judged.
  std::string detail;
};

/// One CAN port of a node of the topology: where its frames appear.
struct PortAddress {
  std::string node;  ///< the node's name
  std::string bus;
  std::uint8_t node_id = 0;
};

/// What a polled read returned. Which fields mean something depends on the judge that asked.
struct Sample {
  TimePoint time{};                    ///< when the read was asked (a read asked inside the window counts)
  std::string error;                   ///< the read did not complete (no answer); the fields below are unset
  std::string text;                    ///< NMT state, simulated signal value, controller state
  std::string unit;                    ///< of a simulated signal
  std::vector<std::uint8_t> data;      ///< SDO upload
  std::optional<std::uint32_t> abort;  ///< SDO abort code
  double load_percent = 0;             ///< bus load
};

/// What a judge needs read while its window is open.
enum class Poll { kNone, kNmt, kSdo, kIo, kController, kBusLoad };

/// "t=5.412 s": scheduler time as seconds since the scenario's start.
std::string TimeText(TimePoint t, TimePoint origin);

class Judge {
 public:
  virtual ~Judge() = default;

  /// What it reads (kNone: frames only).
  virtual Poll Needs() const { return Poll::kNone; }
  /// One line: "EMCY 8130h from quad-6".
  virtual std::string Describe() const = 0;

  /// The window opens and will close at `close` (== open: judged on the first observation).
  /// `open` is the window's time, which may have passed (the runner then hands it the frames seen
  /// since) or lie a little ahead (a frame's end-of-frame time). `origin` is the scenario's start,
  /// for messages.
  void Open(TimePoint origin, TimePoint open, TimePoint close);
  /// A frame (or error frame) seen on `bus` at `time`.
  void Frame(const std::string& bus, const CanFrame& frame, TimePoint time);
  /// A polled read's result.
  void Observe(const Sample& sample);
  /// The window has closed: decides what is still pending.
  void Close();

  const Verdict& verdict() const { return verdict_; }
  bool decided() const { return verdict_.outcome != Outcome::kPending; }
  bool opened() const { return opened_; }
  TimePoint open_time() const { return open_; }
  TimePoint close_time() const { return close_; }

 protected:
  virtual void OnFrame(const std::string& /*bus*/, const CanFrame& /*frame*/, TimePoint /*time*/) {}
  virtual void OnSample(const Sample& /*sample*/) {}
  /// At close, still pending: pass or fail.
  virtual void OnClose() = 0;

  void Pass(TimePoint time, std::string detail);
  void Fail(TimePoint time, std::string detail);
  std::string T(TimePoint t) const { return TimeText(t, origin_); }
  bool instant() const { return open_ == close_; }
  TimePoint close() const { return close_; }
  TimePoint open() const { return open_; }

 private:
  bool InWindow(TimePoint t) const { return opened_ && t >= open_ && t <= close_; }

  Verdict verdict_;
  TimePoint origin_{}, open_{}, close_{};
  bool opened_ = false;
};

/// Names nodes in messages: the node at (bus, node-ID), or "" when the topology has none there.
using NodeNamer = std::function<std::string(const std::string& bus, std::uint8_t node_id)>;

/// The judge of an expectation whose names are resolved: `port` is the node port it names (for
/// kinds about a node), `bus` the bus it names (frames, bus), `namer` names senders in messages.
/// Throws std::invalid_argument for an expectation the loader would have refused (no kind, a
/// value that does not encode).
std::unique_ptr<Judge> MakeJudge(const topology::Expect& expect, const std::optional<PortAddress>& port,
                                 const std::string& bus, NodeNamer namer);

}  // namespace canfleet::scenario
