#pragma once
/// @file A port's outbox of one round (received frames, TX confirmations): a vector whose append
/// stays inline. The broker appends every delivered frame to every receiver's outbox (31 appends
/// for one frame on a 32-port bus), and std::vector::push_back, called out of line from the
/// delivery loop, was a quarter of the broker's time. Internal to the broker.

#include <cstddef>
#include <span>
#include <vector>

#include "orchestrator/broker/port_sink.hpp"

namespace canfleet::broker::detail {

class Outbox {
 public:
  void push_back(const TimedFrame& frame) {
    if (size_ == slots_.size()) Grow();
    slots_[size_++] = frame;
  }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  /// Forgets the frames; keeps the storage (no allocation once it has reached its working size).
  void clear() { size_ = 0; }
  void reserve(std::size_t n) {
    if (n > slots_.size()) slots_.resize(n);
  }
  std::span<const TimedFrame> frames() const { return {slots_.data(), size_}; }

 private:
  [[gnu::noinline]] void Grow() { slots_.resize(slots_.empty() ? 64 : 2 * slots_.size()); }

  std::vector<TimedFrame> slots_;  ///< [0, size_) in use
  std::size_t size_ = 0;
};

}  // namespace canfleet::broker::detail
