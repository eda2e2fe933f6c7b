#pragma once
/// @file One CiA 453 failure-status object (UMAX080311 §2.3.2 6012h, §2.3.9 6112h, §2.3.17 6202h):
/// 2-bit flags, one per monitored quantity, spread over five UNSIGNED32 sub-objects.
///
///   sub 1 Condition   00 the value is lower than its return, 01 higher or equal than its threshold
///                     (between the two it keeps its previous state: the hysteresis of §1.2.3)
///   sub 2 Logic       which condition is a failure: 00 "lower than return", 01 "higher than
///                     threshold", 10/11 the flag is not configured
///   sub 3 Event       01 while the condition has matched the logic for the flag's delay, else 00
///   sub 4 Fault State 01 process (an event is a fault), 11 ignore
///   sub 5 Indication  01 while the event is on and the fault state says process, else 00
///
/// A flag whose logic is not configured keeps its default bits in sub 3 and sub 5 (the manual's
/// defaults print 00 for 6202h's unconfigured Ct1 and 11 for 6012h's unconfigured i/o1). Bits of
/// flags this device does not have are never touched. The previous condition at power-on is the
/// default condition (0xFFF1FFF1: the input above threshold 1 and below return 2), so a value
/// inside a hysteresis band at power-on is no failure.
///
/// The object does not sample anything: the device passes the measured values on each step of its
/// loop, with the time; Pending() says that a delay is counting (the loop must keep running).

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "clock/scheduler.hpp"
#include "node/canopen/od/object_dictionary.hpp"
#include "node/devices/od_ref.hpp"

namespace canfleet::devices::ps {

class FailureStatus {
 public:
  /// @param index 6012h, 6112h or 6202h (sub 1-5 must exist).
  FailureStatus(canopen::ObjectDictionary& od, std::uint16_t index);

  /// Adds a flag at bit `shift`, comparing its value with `threshold` and `return_value` and
  /// waiting `delay` (ms; negative counts as 0). An empty threshold/return OdRef compares with 1
  /// (a yes/no value: 6012h's input/output failure flags).
  void AddFlag(unsigned shift, OdRef threshold, OdRef return_value, OdRef delay);

  /// Evaluates every flag with its value (same order as AddFlag) at `now`. True if a sub changed.
  bool Update(std::span<const std::int64_t> values, TimePoint now);
  /// Any flag's indication is on.
  bool AnyIndication() const;
  /// Flag `shift`'s indication is on.
  bool Indication(unsigned shift) const;
  /// A flag's condition matches its logic but its delay has not run out yet.
  bool Pending() const;
  /// Power-on: pending delays are forgotten (the dictionary was restored to its defaults).
  void Reset();

  const OdRef& condition() const { return condition_; }

 private:
  struct Flag {
    unsigned shift = 0;
    OdRef threshold, return_value, delay;
    std::optional<TimePoint> since;  // the condition has matched the logic since then
    Duration pending_delay{};
    bool indication = false;
  };

  static std::uint32_t DefaultBits(const OdRef& ref, unsigned shift);
  static std::uint32_t With(std::uint32_t word, unsigned shift, std::uint32_t bits);

  OdRef condition_, logic_, event_, fault_state_, indication_;
  std::vector<Flag> flags_;
};

}  // namespace canfleet::devices::ps
