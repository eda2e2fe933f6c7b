#pragma once
/// @file Supply voltage and processor temperature of the data logger (UMAX181001 §1.8, §3.4.68-
/// 3.4.76, Table 26). Read on every application cycle; no delay is given for either fault.
///
///   5020h = VPS.voltage_mV / 1000 (REAL32, V). With 5021h TRUE:
///     V > 5023h  over-voltage  20003000h, clears at V <= 5023h - 5024h
///     V < 5022h  under-voltage 40003000h, clears at V >= 5022h + 5024h
///   5030h = TEMP.temperature_C (REAL32, C). With 5031h TRUE:
///     T > 5032h  over-temperature, clears at T <= 5032h - 5033h ("the value by which the
///                temperature needs to decrease to clear the fault")
/// Table 26 gives the supply codes; it has no over-temperature code, so the device reports CiA
/// 301's 4200h "device temperature" with description 20h (positive overload), channel 0:
/// 1003h 20004200h (README choice). The manual gives no 1029h reaction for either (none taken).
/// As control sources (Table 13 "for diagnostic feedback"): the values in 0.1 V / 0.1 C, no limits
/// (Table 15 "N/A ... 1 (fixed)").

#include <cstddef>
#include <memory>
#include <span>

#include "clock/scheduler.hpp"
#include "node/canopen/stack/canopen_stack.hpp"
#include "node/devices/blocks/signal.hpp"
#include "node/devices/datalogger_tc_analog/datalogger_io.hpp"
#include "node/devices/datalogger_tc_analog/device_fault.hpp"
#include "node/devices/od_ref.hpp"

namespace canfleet::devices::datalogger {

class DiagnosticsBlock {
 public:
  DiagnosticsBlock(canopen::ObjectDictionary& od, const DataLoggerIo& io, Scheduler& scheduler,
                   std::span<canopen::CanopenStack* const> stacks);

  /// Measures and evaluates both faults.
  void Update();

  blocks::Signal SupplySource() const;
  blocks::Signal TemperatureSource() const;

  const DeviceFault& OverVoltage() const { return *over_voltage_; }
  const DeviceFault& UnderVoltage() const { return *under_voltage_; }
  const DeviceFault& OverTemperature() const { return *over_temperature_; }

  void Reset();
  void ResetPort(std::size_t port);

 private:
  const DataLoggerIo& io_;
  OdRef supply_, supply_enable_, under_, over_, supply_hysteresis_;
  OdRef temperature_, temperature_enable_, over_temperature_limit_, temperature_hysteresis_;
  bool over_voltage_flag_ = false;
  bool under_voltage_flag_ = false;
  bool over_temperature_flag_ = false;
  std::unique_ptr<DeviceFault> over_voltage_, under_voltage_, over_temperature_;
};

}  // namespace canfleet::devices::datalogger
