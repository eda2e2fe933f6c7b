#pragma once
/// @file The Axiomatic PS-24-24-350W-CAN (user manual UMAX080311 V1.0.3; CiA DS-453 V2.0): a 24 V in
/// / 24 V out, 350 W DC/DC power supply with an isolated Enable input and CANopen. Its dictionary is
/// generated from power-supply-24v-350w.od (this folder); its behaviour is
///   - the output state machine (output_control.hpp: §1.2.1 source selection, §1.2.1.1 delayed
///     shutdown, §1.2.1.2 enable deglitch, §1.2.3 fault state and Quit Failure),
///   - the physics (power_model.hpp: §1.2.1.3 current limit, §3 hardware protection, regulation),
///   - the input filter (§1.2.1.3 Table 4, 2100h/2101h, the family's blocks::InputFilter),
///   - CiA 453 fault detection (failure_status.hpp: 6112h, 6202h, 6012h) with the EMCY codes of
///     Table 9 (FF04h input failure, FF06h output failure, one entry per kind, DelayedFault),
///   - sleep (sleep_mode.hpp, §1.2.2) and the write checks (ps_validators.hpp).
/// README.md in this folder lists where the manual contradicts itself and what was chosen.
///
/// Timing (design decision 10, "time is events"): the manual's control loop runs every 1 ms (§3
/// "Inputs are measured and output is updated about every 1 ms") on an on-demand PeriodicTick: it
/// ticks while something is in progress (the input filter settling, a delay counting: deglitch,
/// shutdown countdown, failure delays; or a step that changed something) and sleeps otherwise,
/// on its 1 ms grid. Whatever the loop reads wakes it (WakeOnChanges: an input set, an object
/// written, an error raised or cleared; an NMT state change; a reset), and it runs at the next
/// instant of the grid, so the node behaves exactly as a fixed 1 ms loop would. With steady
/// inputs and nothing pending the node schedules nothing.

#include <cstdint>
#include <memory>
#include <optional>
#include <string_view>

#include "node/devices/blocks/input_filter.hpp"
#include "node/devices/delayed_fault.hpp"
#include "node/devices/device.hpp"
#include "node/devices/embedded_eds.hpp"
#include "node/devices/od_ref.hpp"
#include "node/devices/periodic_tick.hpp"
#include "node/devices/power_supply_24v_350w/failure_status.hpp"
#include "node/devices/power_supply_24v_350w/output_control.hpp"
#include "node/devices/power_supply_24v_350w/power_model.hpp"
#include "node/devices/power_supply_24v_350w/ps_io.hpp"
#include "node/devices/power_supply_24v_350w/sleep_mode.hpp"

namespace canfleet::devices {

/// power-supply-24v-350w.eds, generated from power-supply-24v-350w.od by the build and compiled in deflated.
EmbeddedEds PowerSupplyEds();

class PowerSupply final : public Device {
 public:
  static constexpr std::string_view kName = "power-supply-24v-350w";
  static constexpr std::string_view kSummary =
      "Axiomatic PS-24-24-350W-CAN 24 V/350 W DC/DC supply (CiA 453): VIN, ENABLE, LOAD, TEMP -> VOUT, IOUT";
  /// §2.1: "Node ID = 127 (0x7F) and with Baud rate = 125 kbps".
  static constexpr std::uint8_t kFactoryNodeId = 127;
  static constexpr std::uint32_t kFactoryBitRateKbit = 125;
  static constexpr std::string_view kEdsFileName = "power-supply-24v-350w.eds";
  /// §3 "Response Time": inputs measured and output updated about every 1 ms.
  static constexpr Duration kLoopPeriod = std::chrono::milliseconds(1);

  explicit PowerSupply(DeviceOptions options = {});
  ~PowerSupply() override;

  /// Declares the simulated signals (ps_io.hpp) without creating a device (the catalog).
  static void DeclareSignals(SimulatedIo& io);

  std::string_view Name() const override { return kName; }
  void Build(std::size_t port, canopen::ObjectDictionary& od) override;
  void ConfigureStack(std::size_t port, StackSetup& setup) override;
  void Attach(DeviceContext& context) override;

  /// The output state machine's state (PS.state).
  ps::OutputState State() const;
  bool Asleep() const;
  /// The 1 ms loop is ticking (not asleep on its grid): tests check that an idle node does not.
  bool LoopRunning() const;

 private:
  void InstallListeners();
  void OnResetApplication();
  void OnSleepChange(bool asleep);
  /// Something the loop reads changed: it runs at the next instant of its grid.
  void RequestStep();
  /// One pass of the control loop; sets idle_.
  void Step();

  blocks::FilterParams FilterParams() const;
  double CurrentLimit(double vin_filtered_V) const;
  double SetVoltage() const;
  ps::Load CurrentLoad() const;
  bool SleepAllowed() const;
  /// 6011h.1 and 6201h.1 (canfleet's layout, README.md choice 17). True if one changed.
  bool UpdateStatusWords(const ps::OutputPoint& point);
  void Publish(const ps::OutputPoint& point, double limit_A);

  DeviceOptions options_;
  ps::PsIo signals_;
  canopen::ObjectDictionary* od_ = nullptr;
  canopen::CanopenStack* stack_ = nullptr;
  DevicePort* port_ = nullptr;
  Scheduler* scheduler_ = nullptr;
  std::size_t io_subscription_ = 0;

  std::unique_ptr<ps::OutputControl> control_;
  std::unique_ptr<ps::FailureStatus> input_status_, output_status_, device_status_;
  std::unique_ptr<DelayedFault> input_failure_, output_failure_;
  std::unique_ptr<ps::SleepMode> sleep_;
  std::unique_ptr<PeriodicTick> tick_;
  bool idle_ = false;  // the last step changed nothing and nothing is in progress

  ps::InputProtection protection_;
  blocks::InputFilter filter_;
  bool output_on_ = false;

  OdRef filter_type_, filter_constant_, input_actual_, temperature_, output_voltage_, output_current_;
  OdRef set_voltage_, max_voltage_, min_voltage_, range_voltage_, set_current_, max_current_, range_current_;
  OdRef limit_control_, input_delay_, output_delay_, sleep_delay_, device_status_word_, output_status_word_;
};

}  // namespace canfleet::devices
