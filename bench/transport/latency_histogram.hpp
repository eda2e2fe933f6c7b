#pragma once
// Latency histogram of the transport benchmark: 1 us buckets below 1 ms, 100 us buckets up to
// 100 ms, one overflow bucket. Serializable so client processes can report to the driver.

#include <array>
#include <cstdint>
#include <string>

namespace canfleet::bench {

class LatencyHistogram {
 public:
  void Add(std::int64_t ns);
  void Merge(const LatencyHistogram& other);
  /// The latency below which `fraction` of the samples lie, in microseconds (bucket midpoint).
  double Percentile(double fraction) const;
  std::uint64_t Count() const { return count_; }

  /// "index:count,index:count,..." (non-empty buckets only).
  std::string Serialize() const;
  static LatencyHistogram Parse(const std::string& text);

 private:
  static constexpr std::size_t kFine = 1000;   // [0, 1 ms) by 1 us
  static constexpr std::size_t kCoarse = 990;  // [1 ms, 100 ms) by 100 us
  static constexpr std::size_t kBuckets = kFine + kCoarse + 1;
  static std::size_t Index(std::int64_t ns);
  static double Midpoint(std::size_t index);

  std::array<std::uint64_t, kBuckets> buckets_{};
  std::uint64_t count_ = 0;
};

}  // namespace canfleet::bench
