#pragma once
/// @file The two output drives of the AX023241 on their objects (1.4, C3-1.3.17-1.3.31,
/// C3-1.4.7-1.4.23): reads 6310h, 7321h/7323h, 6332h, 2330h/2331h, 2340h-2362h, 2300h, 6340h,
/// 7341h, 6250h/6260h, 6200h/6202h, 2224h/2225h, 2380h; feeds output_drive.hpp; writes 7330h (the
/// commanded field value; left alone under control source 0, where the master writes it) and
/// 2370h (the measured current, mA); publishes OUTn.* and diagnoses the load.
///
/// When outputs are off regardless of their inputs (README.md "Outputs"): NMT stopped; a supply or
/// temperature fault (1.5 "disable ALL outputs"); a control source "Received CAN Message" outside
/// operational (PDOs run in operational only: the family's Quad AX020506 §4.2 rule).
///
/// Load faults (2310h enable, 2311h hysteresis, 2312h delay; 1.5 "a current feedback signal is
/// measured and compared to desired output current value"), through DelayedFault:
///   current below the command by more than 2311h mA (open coil) -> F002h, 1003h 10nnF002h
///   short-circuit protection engaged                            -> F002h, 1003h 20nnF002h
/// with 1029h sub 5 (proportional types) or sub 4 (digital and hotshot). An open load keeps being
/// driven; a short is switched off by the protection whatever 2310h says.

#include <array>
#include <memory>
#include <optional>

#include "clock/scheduler.hpp"
#include "node/canopen/stack/canopen_stack.hpp"
#include "node/devices/blocks/control_source.hpp"
#include "node/devices/delayed_fault.hpp"
#include "node/devices/encoder_dual_valve/encoder_io.hpp"
#include "node/devices/encoder_dual_valve/output_drive.hpp"
#include "node/devices/od_ref.hpp"

namespace canfleet::devices::encoder {

struct OutputConditions {
  canopen::NmtState nmt = canopen::NmtState::kPreOperational;
  /// A supply or processor temperature fault is active (supply_monitor.hpp), or the supply is
  /// below the 7.5 V hardware shutdown (4.1).
  bool all_off = false;
};

class ValveOutputs {
 public:
  using Ms = std::chrono::milliseconds;

  ValveOutputs(canopen::CanopenStack& stack, Scheduler& scheduler, EncoderIo& io);
  ValveOutputs(const ValveOutputs&) = delete;
  ValveOutputs& operator=(const ValveOutputs&) = delete;

  void Update(Ms elapsed, const OutputConditions& conditions, const blocks::ControlSources& sources);
  std::optional<Ms> NextChange() const;
  void Reset();

  /// Table 6 "Output Target Value": 7330h with limits 7321h..7323h (6332h decimals).
  blocks::Signal Target(int n) const;
  /// Table 6 "Output Current Feedback": 2370h, 0..2500 mA.
  blocks::Signal Feedback(int n) const;

  const OutputDrive& drive(int n) const { return drives_[n]; }

 private:
  struct Refs {
    OdRef type, fv_min, fv_max, fv_digits, ramp_up, ramp_down, override_fv, override_response;
    OdRef fault_mode, fault_fv, do_fault_mode, do_fault_state, delay_time, delay_polarity;
    OdRef control_source, control_number, enable_source, enable_number, override_source, override_number;
    OdRef field_value, feedback, error_enable, hysteresis, error_delay, frequency;
  };
  struct Faults {
    std::unique_ptr<DelayedFault> open_ao, short_ao, open_do, short_do;
  };

  DriveConfig Config(int n) const;
  DriveSource Source(const blocks::ControlSources& sources, const OdRef& source, const OdRef& number) const;
  double PwmFrequency(int n) const;
  void Publish(int n);

  EncoderIo& io_;
  std::array<Refs, kOutputs> refs_;
  std::array<Faults, kOutputs> faults_;
  std::array<OutputDrive, kOutputs> drives_;
  OdRef write_state_, polarity_;
};

}  // namespace canfleet::devices::encoder
