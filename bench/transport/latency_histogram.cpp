#include "bench/transport/latency_histogram.hpp"

#include <sstream>

namespace canfleet::bench {

std::size_t LatencyHistogram::Index(std::int64_t ns) {
  const std::int64_t us = ns < 0 ? 0 : ns / 1000;
  if (us < static_cast<std::int64_t>(kFine)) return static_cast<std::size_t>(us);
  const std::int64_t coarse = (us - static_cast<std::int64_t>(kFine)) / 100;
  if (coarse < static_cast<std::int64_t>(kCoarse)) return kFine + static_cast<std::size_t>(coarse);
  return kBuckets - 1;
}

double LatencyHistogram::Midpoint(std::size_t index) {
  if (index < kFine) return static_cast<double>(index) + 0.5;
  if (index < kFine + kCoarse)
    return static_cast<double>(kFine) + static_cast<double>(index - kFine) * 100 + 50;
  return 100'000;
}

void LatencyHistogram::Add(std::int64_t ns) {
  ++buckets_[Index(ns)];
  ++count_;
}

void LatencyHistogram::Merge(const LatencyHistogram& other) {
  for (std::size_t i = 0; i < kBuckets; ++i)
    buckets_[i] += other.buckets_[i];
  count_ += other.count_;
}

double LatencyHistogram::Percentile(double fraction) const {
  if (count_ == 0) return 0;
  const auto rank = static_cast<std::uint64_t>(fraction * static_cast<double>(count_ - 1));
  std::uint64_t seen = 0;
  for (std::size_t i = 0; i < kBuckets; ++i) {
    seen += buckets_[i];
    if (seen > rank) return Midpoint(i);
  }
  return Midpoint(kBuckets - 1);
}

std::string LatencyHistogram::Serialize() const {
  std::string out;
  for (std::size_t i = 0; i < kBuckets; ++i)
    if (buckets_[i] != 0)
      out += (out.empty() ? "" : ",") + std::to_string(i) + ":" + std::to_string(buckets_[i]);
  return out.empty() ? "-" : out;
}

LatencyHistogram LatencyHistogram::Parse(const std::string& text) {
  LatencyHistogram h;
  std::istringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    const auto colon = item.find(':');
    if (colon == std::string::npos) continue;
    const auto index = std::stoul(item.substr(0, colon));
    const auto count = std::stoull(item.substr(colon + 1));
    if (index >= kBuckets) continue;
    h.buckets_[index] += count;
    h.count_ += count;
  }
  return h;
}

}  // namespace canfleet::bench
