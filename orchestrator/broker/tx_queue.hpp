#pragma once
/// @file A port's transmit queue: a fixed-capacity FIFO ring, allocated once when the port
/// attaches, like a CAN driver's TX queue (Linux: the qdisc in front of the controller).

#include <cstddef>
#include <cstdint>
#include <vector>

#include "bus/bus_port.hpp"
#include "bus/can_frame.hpp"

namespace canfleet::broker::detail {

struct QueuedFrame {
  CanFrame frame;
  BusTime submitted{};      ///< broker time of Submit: the frame may join arbitrations from then on
  std::uint64_t seq = 0;    ///< bus-wide submission order (ties in arbitration, unpaced FIFO)
  bool repetition = false;  ///< a repeated transfer scheduled by a duplicate rule
  bool babble = false;      ///< a babbling idiot's frame (Port::babble), not from the queue
};

class TxQueue {
 public:
  explicit TxQueue(std::size_t capacity) : slots_(capacity) {}

  bool empty() const { return size_ == 0; }
  bool full() const { return size_ == slots_.size(); }
  std::size_t size() const { return size_; }
  std::size_t capacity() const { return slots_.size(); }

  /// Calls `f` with each queued frame, oldest first.
  template <class F>
  void ForEach(F&& f) const {
    std::size_t i = head_;
    for (std::size_t n = 0; n < size_; ++n) {
      f(slots_[i]);
      if (++i == slots_.size()) i = 0;
    }
  }

  QueuedFrame& front() { return slots_[head_]; }
  const QueuedFrame& front() const { return slots_[head_]; }

  /// False (and nothing stored) when full.
  bool push_back(const QueuedFrame& frame) {
    if (full()) return false;
    std::size_t tail = head_ + size_;
    if (tail >= slots_.size()) tail -= slots_.size();
    slots_[tail] = frame;
    ++size_;
    return true;
  }
  void pop_front() {
    if (++head_ == slots_.size()) head_ = 0;
    --size_;
  }
  void clear() {
    head_ = 0;
    size_ = 0;
  }

 private:
  std::vector<QueuedFrame> slots_;
  std::size_t head_ = 0;
  std::size_t size_ = 0;
};

}  // namespace canfleet::broker::detail
