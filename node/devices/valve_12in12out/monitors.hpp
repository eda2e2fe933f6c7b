#pragma once
/// @file Supply voltage and processor temperature monitoring (UMAX020411A §1.10, §3.4.99-3.4.107,
/// §3.2.4 Table 33).
///
/// - 5020h (REAL32 V) and 5030h (REAL32 degC) follow the simulated VPS.voltage_mV (/1000) and
///   TEMP.temperature_C.
/// - Supply (5021h TRUE): below 5022h -> under-voltage 40003000h, above 5023h -> over-voltage
///   20003000h (EMCY 3000h "generic voltage"); under clears at 5022h + 5024h or more, over at
///   5023h - 5024h or less.
/// - Temperature (5031h TRUE): above 5032h -> over-temperature, cleared at 5032h - 5033h or less.
///   Table 33 has no code for it; §4 "Diagnostics" says it is reported: 20004200h (description 20h
///   "positive overload" as for the over-voltage, EMCY 4200h "device temperature", CiA 301).
/// No delay is given for either: a fault acts on the run that sees it. No 1029h sub-index names
/// these faults: no NMT reaction. A supply fault shuts the outputs off (§4 "under-/overvoltage
/// protection: hardware shutdown"); an over-temperature only reports (README.md).

#include "clock/scheduler.hpp"
#include "node/canopen/stack/canopen_stack.hpp"
#include "node/devices/delayed_fault.hpp"
#include "node/devices/od_ref.hpp"
#include "node/devices/valve_12in12out/valve_io.hpp"

namespace canfleet::devices::valve {

class Monitors {
 public:
  Monitors(canopen::CanopenStack& stack, Scheduler& scheduler, const ValveIo& io);

  void Run();
  void Reset();
  bool SupplyFault() const { return under_active_ || over_active_; }

 private:
  const ValveIo& io_;
  OdRef voltage_, supply_enable_, under_, over_, supply_hysteresis_;
  OdRef temperature_, temperature_enable_, temperature_over_, temperature_hysteresis_;
  DelayedFault under_fault_, over_fault_, temperature_fault_;
  bool under_active_ = false;
  bool over_active_ = false;
  bool hot_active_ = false;
};

}  // namespace canfleet::devices::valve
