#pragma once
/// @file Supply voltage and processor temperature (AX023241 1.5 "Fault Detection Objects",
/// C3-1.4.63-1.4.69, 4.1): 5020h supply (V) and 5030h CPU temperature (degC) as measured; 5040h
/// the fault detection field values sub 1 temperature, 2 and 3 supply, in the thresholds' unit
/// (0.1 degC / 0.1 V: 5041h 1100 = 110.0 degC, 500 = 50.0 V, 90 = 9.0 V; README.md).
///
/// Per fault, enabled by 5050h (bit 0 supply, bit 1 temperature; bit 2 has no meaning):
///   temperature  set when >= 5041h.1, cleared when <= 5042h.1, delay 5051h.1
///   over-voltage set when >= 5041h.2, cleared when <= 5042h.2, delay 5051h.2
///   under-voltage set when <= 5041h.3, cleared when >= 5042h.3, delay 5051h.3 (sub 3 is unnamed)
/// A fault "needs to be present" 5051h x 100 ms "to flag an error"; it then raises its EMCY (the
/// family's codes, README.md): 3000h with 1003h 20003000h (over) / 40003000h (under), 4200h with
/// 20004200h (over-temperature); 1029h sub 6 ("other faults"). While one is active "ALL outputs"
/// are off, until the value is back at its clear threshold. Below 7.5 V the outputs are off
/// anyway (4.1: hardware and software shutdown), without an EMCY.
///
/// Time is events: a fault waiting out its delay asks for one evaluation at the end of it.

#include <array>
#include <chrono>
#include <memory>
#include <optional>

#include "clock/scheduler.hpp"
#include "node/canopen/stack/canopen_stack.hpp"
#include "node/devices/delayed_fault.hpp"
#include "node/devices/encoder_dual_valve/encoder_io.hpp"
#include "node/devices/od_ref.hpp"

namespace canfleet::devices::encoder {

class SupplyMonitor {
 public:
  using Ms = std::chrono::milliseconds;
  static constexpr double kShutdownVoltage = 7.5;

  SupplyMonitor(canopen::CanopenStack& stack, Scheduler& scheduler, EncoderIo& io);
  SupplyMonitor(const SupplyMonitor&) = delete;
  SupplyMonitor& operator=(const SupplyMonitor&) = delete;

  void Update(Ms elapsed);
  /// Outputs must be off: a fault is active, or the supply is below the shutdown voltage.
  bool OutputsOff() const;
  std::optional<Ms> NextChange() const;
  void Reset();

  enum Watch : std::size_t { kTemperature = 0, kOverVoltage = 1, kUnderVoltage = 2 };
  bool Active(Watch w) const { return watches_[w].active; }

 private:
  struct State {
    bool flag = false;
    Ms held{0};
    bool active = false;
    Ms delay{0};
    std::unique_ptr<DelayedFault> fault;
  };
  void Step(State& s, bool enabled, bool set, bool clear, Ms delay, Ms elapsed);

  EncoderIo& io_;
  std::array<State, 3> watches_;
  OdRef supply_, temperature_, enable_;
  std::array<OdRef, 3> field_, set_, clear_, delay_;
  double supply_V_ = 24.0;
};

}  // namespace canfleet::devices::encoder
