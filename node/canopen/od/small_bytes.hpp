#pragma once
/// @file SmallBytes: the encoded bytes of one OD value, kept inline up to 8 bytes. Nearly every
/// value, default and limit of a dictionary is a number of 1 to 8 bytes; as a std::vector each took
/// 24 bytes plus a heap block of at least 32, four times per sub-object, for the 2500 sub-objects
/// of a valve controller (idle RSS, bench/idle/README.md). Strings and domains longer than 8 bytes
/// go to the heap.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <iterator>
#include <memory>
#include <span>
#include <vector>

namespace canfleet::canopen {

class SmallBytes {
 public:
  using value_type = std::uint8_t;
  using size_type = std::size_t;
  using iterator = std::uint8_t*;
  using const_iterator = const std::uint8_t*;

  SmallBytes() = default;
  SmallBytes(std::span<const std::uint8_t> bytes) { Assign(bytes.data(), bytes.size()); }     // NOLINT
  SmallBytes(const std::vector<std::uint8_t>& bytes) { Assign(bytes.data(), bytes.size()); }  // NOLINT
  SmallBytes(std::initializer_list<std::uint8_t> bytes) { Assign(bytes.begin(), bytes.size()); }
  SmallBytes(const SmallBytes& other) { Assign(other.data(), other.size()); }
  SmallBytes(SmallBytes&& other) noexcept { Take(other); }
  ~SmallBytes() { Free(); }

  SmallBytes& operator=(const SmallBytes& other) {
    if (this != &other) Assign(other.data(), other.size());
    return *this;
  }
  SmallBytes& operator=(SmallBytes&& other) noexcept {
    if (this != &other) {
      Free();
      Take(other);
    }
    return *this;
  }

  /// Replaces the contents; reuses the buffer when it is large enough (no allocation per RPDO).
  template <typename It>
  void assign(It first, It last) {
    if constexpr (std::contiguous_iterator<It>) {
      Assign(std::to_address(first), static_cast<std::size_t>(last - first));
    } else {
      const std::vector<std::uint8_t> copy(first, last);
      Assign(copy.data(), copy.size());
    }
  }
  void resize(std::size_t n) {
    if (n > capacity()) Grow(n);
    if (n > size_) std::memset(data() + size_, 0, n - size_);
    size_ = static_cast<std::uint32_t>(n);
  }
  void clear() { size_ = 0; }

  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  std::uint8_t* data() { return capacity_ ? heap_ : inline_; }
  const std::uint8_t* data() const { return capacity_ ? heap_ : inline_; }
  std::uint8_t* begin() { return data(); }
  std::uint8_t* end() { return data() + size_; }
  const std::uint8_t* begin() const { return data(); }
  const std::uint8_t* end() const { return data() + size_; }
  std::uint8_t& operator[](std::size_t i) { return data()[i]; }
  std::uint8_t operator[](std::size_t i) const { return data()[i]; }

  /// A copy as a vector, for the interfaces that take Bytes.
  operator std::vector<std::uint8_t>() const { return {begin(), end()}; }  // NOLINT

  friend bool operator==(const SmallBytes& a, const SmallBytes& b) {
    return std::equal(a.begin(), a.end(), b.begin(), b.end());
  }
  friend bool operator==(const SmallBytes& a, const std::vector<std::uint8_t>& b) {
    return std::equal(a.begin(), a.end(), b.begin(), b.end());
  }

 private:
  static constexpr std::size_t kInline = 8;

  std::size_t capacity() const { return capacity_ ? capacity_ : kInline; }
  void Assign(const std::uint8_t* bytes, std::size_t n) {
    if (n > capacity()) Grow(n);
    if (n) std::memmove(data(), bytes, n);
    size_ = static_cast<std::uint32_t>(n);
  }
  // Grows to exactly n bytes, keeping the contents (values keep their length for life).
  void Grow(std::size_t n) {
    auto* bigger = new std::uint8_t[n];
    if (size_) std::memcpy(bigger, data(), size_);
    Free();
    heap_ = bigger;
    capacity_ = static_cast<std::uint32_t>(n);
  }
  void Free() {
    if (capacity_) delete[] heap_;
    capacity_ = 0;
  }
  void Take(SmallBytes& other) {
    size_ = other.size_;
    capacity_ = other.capacity_;
    if (capacity_)
      heap_ = other.heap_;
    else
      std::memcpy(inline_, other.inline_, kInline);
    other.capacity_ = 0;
    other.size_ = 0;
  }

  union {
    std::uint8_t inline_[kInline] = {};
    std::uint8_t* heap_;
  };
  std::uint32_t size_ = 0;
  std::uint32_t capacity_ = 0;  ///< 0: the bytes are inline
};

}  // namespace canfleet::canopen
