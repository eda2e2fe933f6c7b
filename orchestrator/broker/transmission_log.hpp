#pragma once
/// @file The recent transfers of one bus (a ring sized from the bitrate and the statistics
/// window), from which bus load, frames/s and the busiest identifiers are computed on demand.
/// Recording is one store per transfer; the cost of the statistics is paid by whoever asks.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "bus/bus_port.hpp"
#include "bus/can_frame.hpp"
#include "orchestrator/broker/stats.hpp"

namespace canfleet::broker::detail {

class TransmissionLog {
 public:
  explicit TransmissionLog(std::size_t capacity) : records_(capacity) {}

  /// One transfer attempt occupying the bus from `start` to `end` (equal on an unpaced bus).
  void Record(BusTime start, BusTime end, const CanFrame& frame, bool error) {
    Entry& e = records_[next_];
    e.start = start;
    e.end = end;
    e.id = frame.id;
    e.extended = frame.extended();
    e.error = error;
    if (++next_ == records_.size()) {
      next_ = 0;
      wrapped_ = true;
    }
  }

  /// A transfer on the wire that is not recorded yet.
  struct Ongoing {
    BusTime start{};
    BusTime end{};
  };

  /// Fills the window figures of `stats` for the time range (now - window, now]. `created` is when
  /// the bus was created (a young bus has a shorter window); the part of `ongoing` inside the
  /// range counts as busy. When the ring no longer reaches back to the start of the range, the
  /// figures cover what it holds.
  void Summarize(BusTime now, BusTime window, BusTime created, const std::optional<Ongoing>& ongoing,
                 std::size_t top_n, BusStats& stats) const;

 private:
  struct Entry {
    BusTime start{};
    BusTime end{};
    std::uint32_t id = 0;
    bool extended = false;
    bool error = false;
  };

  std::vector<Entry> records_;
  std::size_t next_ = 0;
  bool wrapped_ = false;
};

}  // namespace canfleet::broker::detail
