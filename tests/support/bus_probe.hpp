#pragma once
/// @file Test helpers: write frames in candump notation ("601#4018100100000000") and a probe port
/// that plays the master's side of a loopback bus and records what it receives.

#include <deque>
#include <string>
#include <string_view>
#include <vector>

#include "bus/can_frame.hpp"
#include "bus/loopback_bus.hpp"

namespace canfleet::test {

/// Parses candump's compact notation: "123#DEADBEEF", "1ABCDEF0#00" (8 hex digits = 29-bit),
/// "701#R" or "701#R1" (remote, optional DLC). Spaces and dots in the data are ignored.
/// Throws std::invalid_argument on malformed text (tests only).
CanFrame Frame(std::string_view text);

/// A port that records every frame it receives.
class BusProbe {
 public:
  explicit BusProbe(LoopbackBus& bus, std::string name = "probe");

  /// Sends a frame (candump notation or a frame) from the probe.
  void Send(std::string_view text) { port_.Send(Frame(text)); }
  void Send(const CanFrame& frame) { port_.Send(frame); }

  /// Every frame received since the last Take/Clear, in candump notation.
  std::vector<std::string> Received() const;
  /// Returns and forgets the received frames.
  std::vector<std::string> Take();
  /// Returns and forgets the oldest received frame; "" if none.
  std::string Next();
  void Clear() { frames_.clear(); }
  std::size_t Count() const { return frames_.size(); }

  LoopbackPort& port() { return port_; }

 private:
  LoopbackPort& port_;
  std::deque<CanFrame> frames_;
};

}  // namespace canfleet::test
