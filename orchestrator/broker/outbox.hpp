#pragma once
/// @file Append buffers of one round (a port's TX confirmations, its delivery exceptions, the
/// bus's shared round): vectors whose append stays inline. std::vector::push_back, called out of
/// line from the delivery loop, was a quarter of the broker's time. Internal to the broker.

#include <cstddef>
#include <span>
#include <vector>

#include "orchestrator/broker/port_sink.hpp"

namespace canfleet::broker::detail {

template <class T>
class AppendBuffer {
 public:
  void push_back(const T& item) {
    if (size_ == slots_.size()) Grow();
    slots_[size_++] = item;
  }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  /// Forgets the frames; keeps the storage (no allocation once it has reached its working size).
  void clear() { size_ = 0; }
  void reserve(std::size_t n) {
    if (n > slots_.size()) slots_.resize(n);
  }
  std::span<const T> items() const { return {slots_.data(), size_}; }
  const T& operator[](std::size_t i) const { return slots_[i]; }

 private:
  [[gnu::noinline]] void Grow() { slots_.resize(slots_.empty() ? 64 : 2 * slots_.size()); }

  std::vector<T> slots_;  ///< [0, size_) in use
  std::size_t size_ = 0;
};

/// A port's TX confirmations of one round.
using Outbox = AppendBuffer<TimedFrame>;

}  // namespace canfleet::broker::detail
