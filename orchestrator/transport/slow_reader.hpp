#pragma once
/// @file A client that cannot keep up (issue 32, "bounded everything"): while its queue is full,
/// what is delivered for it is dropped and counted (a CAN controller's overrun); once that has
/// lasted a limit without the client catching up, it is disconnected with the reason logged,
/// rather than held with its queue full for ever. Used by the broker's node sessions, the
/// socketcand sessions and the control API's sessions (dumps). Pure: the caller gives the time.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

namespace canfleet::transport {

class SlowReader {
 public:
  using Clock = std::chrono::steady_clock;

  explicit SlowReader(std::chrono::milliseconds limit) : limit_(limit) {}

  /// `count` items were dropped at `now` because the client's queue is full. True once the
  /// episode (from its first drop) has lasted the limit: disconnect, with Reason().
  bool Dropped(std::uint64_t count, Clock::time_point now) {
    if (!since_) since_ = now;
    dropped_ += count;
    return now - *since_ >= limit_;
  }
  /// The client read: the episode ends. Returns how many items it lost (0: there was none).
  std::uint64_t CaughtUp() {
    const auto lost = dropped_;
    since_.reset();
    dropped_ = 0;
    return lost;
  }
  bool Dropping() const { return since_.has_value(); }
  std::uint64_t dropped() const { return dropped_; }
  /// "not reading: 1234 frames dropped over 10 s" (`what`: "frames").
  std::string Reason(const char* what) const {
    const auto ms = limit_.count();
    return "not reading: " + std::to_string(dropped_) + " " + what + " dropped over " +
           (ms % 1000 == 0 ? std::to_string(ms / 1000) + " s" : std::to_string(ms) + " ms");
  }

 private:
  std::chrono::milliseconds limit_;
  std::optional<Clock::time_point> since_;
  std::uint64_t dropped_ = 0;
};

}  // namespace canfleet::transport
