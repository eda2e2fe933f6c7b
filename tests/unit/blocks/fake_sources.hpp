#pragma once
// A product's wiring for the block tests: a source table and a map of (kind, number) -> Signal
// that the tests fill, standing in for the product's objects.
#include <map>
#include <span>
#include <utility>

#include "node/devices/blocks/control_source.hpp"

namespace canfleet::devices::blocks::test {

class FakeSources {
 public:
  explicit FakeSources(std::span<const SourceType> types)
      : sources_(types, [this](SourceKind kind, std::uint8_t number) {
          ++reads_;
          const auto it = signals_.find({kind, number});
          return it == signals_.end() ? Signal::NotAvailable() : it->second;
        }) {}
  FakeSources(const FakeSources&) = delete;
  FakeSources& operator=(const FakeSources&) = delete;

  void Set(SourceKind kind, std::uint8_t number, const Signal& s) { signals_[{kind, number}] = s; }
  const ControlSources& sources() const { return sources_; }
  int reads() const { return reads_; }

 private:
  std::map<std::pair<SourceKind, std::uint8_t>, Signal> signals_;
  ControlSources sources_;
  int reads_ = 0;
};

/// A raw value with limits, e.g. an AI field value 2500 mV in 500..4500 (3 digits).
inline Signal Ranged(double value, double min, double max, std::uint8_t digits = 0) {
  Signal s;
  s.value = value;
  s.min = min;
  s.max = max;
  s.decimal_digits = digits;
  return s;
}

inline Signal Faulted(Signal s) {
  s.error = true;
  return s;
}

}  // namespace canfleet::devices::blocks::test
