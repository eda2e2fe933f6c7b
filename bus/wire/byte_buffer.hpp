#pragma once
/// @file A growable byte buffer that, unlike std::vector<uint8_t>, does not zero what it grows
/// by: the writers fill every byte they reserve, so zeroing would only cost time on the hot path.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <span>
#include <utility>

namespace canfleet::wire {

class ByteBuffer {
 public:
  ByteBuffer() = default;
  ByteBuffer(ByteBuffer&&) noexcept = default;
  ByteBuffer& operator=(ByteBuffer&&) noexcept = default;

  std::uint8_t* data() { return data_.get(); }
  const std::uint8_t* data() const { return data_.get(); }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  std::span<const std::uint8_t> bytes() const { return {data_.get(), size_}; }

  /// Grows the contents by `n` uninitialised bytes and returns where they start. Reallocates
  /// (doubling) only when the capacity is exceeded.
  std::uint8_t* Extend(std::size_t n) {
    if (capacity_ - size_ < n) Reserve(std::max(size_ + n, capacity_ * 2));
    std::uint8_t* at = data_.get() + size_;
    size_ += n;
    return at;
  }
  /// Drops bytes from the end.
  void Shrink(std::size_t new_size) { size_ = std::min(size_, new_size); }
  /// Empties the buffer; keeps the storage.
  void clear() { size_ = 0; }

  void Reserve(std::size_t capacity) {
    if (capacity <= capacity_) return;
    auto bigger = std::make_unique_for_overwrite<std::uint8_t[]>(capacity);
    if (size_ != 0) std::memcpy(bigger.get(), data_.get(), size_);
    data_ = std::move(bigger);
    capacity_ = capacity;
  }

  void swap(ByteBuffer& other) noexcept {
    std::swap(data_, other.data_);
    std::swap(size_, other.size_);
    std::swap(capacity_, other.capacity_);
  }

 private:
  std::unique_ptr<std::uint8_t[]> data_;
  std::size_t size_ = 0;
  std::size_t capacity_ = 0;
};

}  // namespace canfleet::wire
