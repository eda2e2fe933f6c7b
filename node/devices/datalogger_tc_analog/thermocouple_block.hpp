#pragma once
/// @file The four thermocouple inputs of the data logger (UMAX181001 §1.2, §3.3.2-3.3.4, §3.4.19-
/// 3.4.26, Table 26).
///
/// Conversion (§4: "The 4 TC inputs new measured value is available every 400 ms"), per channel n:
///   6130h.n  TC Input PV        measured EMF in uV (§1.2 "raw microvolt reading"; §3.3.3's "mV"
///                               cannot hold a reading in an INTEGER16), saturated at +-32767
///   2161h    TC CJ Input PV     cold-junction temperature in 0.1 C (the TC resolution, §4)
///   2162h.n  TC CJ Output FV    E(T_cj) of channel n's type in uV ("in mV" per type, §3.4.21)
///   6100h.n  TC Input FV        the temperature in 0.1 C, cold-junction compensated if 2160h.n
/// An open thermocouple (TCn.open) is an ADC over-range: 6130h.n and 6100h.n read 32767 and the
/// open-circuit fault 10t0F002h is active (t0 = 10h..40h).
///
/// Limits (§1.2, §3.4.22-3.4.26), checked against 6100h on every cycle, no enable, no delay:
///   FV < 2170h low warning 01t0F011h     clears at FV >= 2170h + 2174h
///   FV > 2171h high warning 02t0F011h    clears at FV <= 2171h - 2174h
///   FV < 2172h low shutdown 04t0F011h    clears at FV >= 2172h + 2174h
///   FV > 2173h high shutdown 08t0F011h   clears at FV <= 2173h - 2174h
/// Each flag is its own 1003h entry; all take the 1029h sub 3 reaction. The factory thresholds are
/// all 0, so a TC at room temperature trips both high flags (README "Factory thresholds").
/// While a channel is open its limit flags are not evaluated (cleared).

#include <array>
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

class ThermocoupleBlock {
 public:
  /// Flags of one channel, in the order of Table 26's descriptions 01h, 02h, 04h, 08h.
  enum Limit : std::size_t { kLowWarning, kHighWarning, kLowShutdown, kHighShutdown, kLimits };

  ThermocoupleBlock(canopen::ObjectDictionary& od, const DataLoggerIo& io, Scheduler& scheduler,
                    std::span<canopen::CanopenStack* const> stacks);

  /// One conversion of all four channels from the pins: 6130h, 2161h, 2162h, 6100h.
  void Convert();
  /// The limit and open-circuit flags against the current 6100h, and their faults.
  void EvaluateFaults();

  /// Control source "Thermocouple Degree Measured" (Table 13/15): 6100h.n, limits 2170h..2171h,
  /// 1 decimal; in error while open.
  blocks::Signal TemperatureSource(int ch) const;
  /// Control source "Thermocouple Cold Junction mV Measured": 2162h.n in uV (3 decimals of mV),
  /// limits E(-40 C)..E(210 C) of the channel's type (Table 15's fixed -40..210, README C25).
  blocks::Signal ColdJunctionSource(int ch) const;

  bool Flag(int ch, Limit limit) const { return channels_.at(static_cast<std::size_t>(ch)).flags[limit]; }
  const DeviceFault& LimitFault(int ch, Limit limit) const {
    return *channels_.at(static_cast<std::size_t>(ch)).limit_faults[limit];
  }
  const DeviceFault& OpenFault(int ch) const {
    return *channels_.at(static_cast<std::size_t>(ch)).open_fault;
  }

  /// Reset application: flags cleared (the faults of each port are reset separately).
  void Reset();
  /// Port `port` forgot its errors.
  void ResetPort(std::size_t port);

 private:
  struct Channel {
    OdRef type, cj_enabled, field_value, process_value, cj_output;
    std::array<OdRef, kLimits> thresholds;
    OdRef hysteresis;
    bool open = false;
    std::array<bool, kLimits> flags{};
    std::array<std::unique_ptr<DeviceFault>, kLimits> limit_faults;
    std::unique_ptr<DeviceFault> open_fault;
  };

  const DataLoggerIo& io_;
  OdRef cj_pv_;
  std::array<Channel, kThermocouples> channels_;
};

}  // namespace canfleet::devices::datalogger
