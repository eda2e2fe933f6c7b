#pragma once
/// @file The submission order of an unpaced bus: one entry per accepted frame, bus-wide, so that
/// the oldest head among all ports' TX queues is found in O(1) instead of by a scan of the ports.
/// Internal to the broker.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace canfleet::broker::detail {

struct Port;

/// A growable FIFO ring of (port, sequence number) in submission order.
///
/// Why the front answers "which port's head is the oldest": each port's queue is FIFO and
/// sequence numbers rise with every Submit on the bus, so the entries of a port's queued frames
/// appear here in queue order, and every entry before a port's head entry belongs to a frame that
/// left its queue (sent, or dropped at bus-off or detach). Such stale entries are discarded lazily
/// when they reach the front (an entry is stale when its sequence number is not the one at the
/// head of its port's queue), so the first live entry is the head with the lowest sequence number.
/// Each entry is pushed and popped once: amortised O(1) per frame.
///
/// The ring grows (doubling) when full and never shrinks, so the steady state allocates nothing.
class SubmissionOrder {
 public:
  struct Entry {
    Port* port;
    std::uint64_t seq;
  };

  SubmissionOrder() : slots_(1024) {}

  bool empty() const { return size_ == 0; }
  std::size_t size() const { return size_; }
  const Entry& front() const { return slots_[head_]; }

  void push_back(Entry entry) {
    if (size_ == slots_.size()) Grow();
    std::size_t tail = head_ + size_;
    if (tail >= slots_.size()) tail -= slots_.size();
    slots_[tail] = entry;
    ++size_;
  }
  void pop_front() {
    if (++head_ == slots_.size()) head_ = 0;
    --size_;
  }
  /// Removes the entries `drop(entry)` selects, keeping the order (in place; used before ports
  /// are freed, so no entry outlives its port).
  template <class Drop>
  void EraseIf(Drop&& drop) {
    const std::size_t n = slots_.size();
    std::size_t kept = 0;
    for (std::size_t i = 0; i < size_; ++i) {
      const Entry e = slots_[(head_ + i) % n];
      if (!drop(e)) slots_[(head_ + kept++) % n] = e;
    }
    size_ = kept;
  }

 private:
  void Grow() {
    std::vector<Entry> bigger(slots_.size() * 2);
    for (std::size_t i = 0; i < size_; ++i)
      bigger[i] = slots_[(head_ + i) % slots_.size()];
    slots_.swap(bigger);
    head_ = 0;
  }

  std::vector<Entry> slots_;
  std::size_t head_ = 0;
  std::size_t size_ = 0;
};

}  // namespace canfleet::broker::detail
