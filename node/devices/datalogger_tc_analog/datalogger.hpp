#pragma once
/// @file The Axiomatic Data Logger AX181001 (TC/Analog Inputs to CAN Controller, user manual
/// UMAX181001 V1.01, CiA DS-404 device): 4 thermocouple inputs, 7 analog and 3 universal inputs,
/// 12 lookup tables, 4 logic blocks and 6 math blocks, on TWO CAN ports that "share
/// manufacturer-specific objects but have separate Communication Objects" (§3). Its dictionary
/// is datalogger-tc-analog.od (this folder, one port's view); README.md lists where the manual
/// contradicts itself and the policies where it is silent.
///
/// Two ports (framework: Device::SharedObjects, DeviceNode): each port has its own 1000h-1FFFh,
/// node-ID, bit rate, NMT state, heartbeat, PDOs, SDO server, EMCY, 1001h/1003h and 1029h; the
/// application objects 2000h-FFFFh are one set, owned by port 1's dictionary and borrowed by
/// port 2's. The blocks run once, on port 1's dictionary; device faults go to both ports
/// (device_fault.hpp). Store/restore on either port covers both ports (README "Storage"); a reset
/// node on either port resets the device's application (README "Reset node").
///
/// Time is events (design decision 10): nothing runs while the inputs are steady. An application
/// cycle (inputs -> diagnostics -> math -> tables -> logic -> faults) runs on 10 ms scan boundaries
/// (§4: "A complete scan of all inputs is 10 ms. New measured values are ready every 10 ms") after
/// a pin changes, a parameter is written or an RPDO arrives, and keeps running every 10 ms only
/// while a filter settles, a lookup table ramps or outputs still move; a span delay or a time
/// response's hold wakes it once at its end. The thermocouples convert on 400 ms boundaries (§4:
/// "The 4 TC inputs new measured value is available every 400 ms") after a TC pin or TC parameter
/// changed.

#include <array>
#include <chrono>
#include <memory>
#include <optional>
#include <string_view>
#include <vector>

#include "node/devices/blocks/signal.hpp"
#include "node/devices/datalogger_tc_analog/analog_block.hpp"
#include "node/devices/datalogger_tc_analog/datalogger_io.hpp"
#include "node/devices/datalogger_tc_analog/diagnostics_block.hpp"
#include "node/devices/datalogger_tc_analog/program_blocks.hpp"
#include "node/devices/datalogger_tc_analog/thermocouple_block.hpp"
#include "node/devices/device.hpp"
#include "node/devices/embedded_eds.hpp"

namespace canfleet::devices {

/// datalogger-tc-analog.eds, generated from datalogger-tc-analog.od by the build and compiled in deflated.
EmbeddedEds DataLoggerEds();

class DataLogger final : public Device {
 public:
  static constexpr std::string_view kName = "datalogger-tc-analog";
  static constexpr std::string_view kSummary =
      "Axiomatic Data Logger AX181001 (CiA 404): 4 TC, 7 AI, 3 universal inputs, 2 CAN ports";
  /// §4: a complete scan of all inputs.
  static constexpr Duration kScanPeriod = std::chrono::milliseconds(10);
  /// §4: a new thermocouple value every 400 ms.
  static constexpr Duration kConversionPeriod = std::chrono::milliseconds(400);

  /// `options.ports` comes from the catalog entry (2).
  explicit DataLogger(DeviceOptions options = {});
  ~DataLogger() override;

  std::string_view Name() const override { return kName; }
  std::optional<ObjectRange> SharedObjects() const override { return ObjectRange{0x2000, 0xFFFF}; }
  void Build(std::size_t port, canopen::ObjectDictionary& od) override;
  void ConfigureStack(std::size_t port, StackSetup& setup) override;
  void Attach(DeviceContext& context) override;

  const datalogger::AnalogInputBlock& analog() const { return *analog_; }
  const datalogger::ThermocoupleBlock& thermocouples() const { return *thermocouples_; }
  const datalogger::DiagnosticsBlock& diagnostics() const { return *diagnostics_; }
  const datalogger::ProgramBlocks& program() const { return *program_; }
  /// Application cycles and TC conversions run since construction (tests count wake-ups).
  std::uint64_t Cycles() const { return cycles_; }
  std::uint64_t Conversions() const { return conversions_; }

 private:
  void OnResetApplication(std::size_t port);
  void RestartApplication();
  void OnPinChanged(const IoSignal& signal);
  void OnParameterWritten(const canopen::SubObject& sub, canopen::Origin origin);
  void RequestCycle();
  void RequestConversion();
  void OnCycle();
  void OnConversion();
  /// Runs the inputs' filters and delays up to now with the pins as last latched.
  void AdvanceInputs();
  /// The first scan boundary (power-on + k x period) at or after `t`.
  TimePoint BoundaryAtOrAfter(TimePoint t, Duration period) const;
  blocks::Signal ResolveInput(blocks::SourceKind kind, std::uint8_t number) const;
  void InstallParameterListeners();
  void InstallStorageOnBothPorts();
  void InstallSupplyValidators();

  DeviceOptions options_;
  datalogger::DataLoggerIo signals_;
  canopen::ObjectDictionary* shared_od_ = nullptr;  // port 1's dictionary (owns 2000h-FFFFh)
  Scheduler* scheduler_ = nullptr;
  std::vector<canopen::CanopenStack*> stacks_;
  std::vector<bool> powered_;  // the port's stack has started (its first reset is the power-on)

  std::unique_ptr<datalogger::AnalogInputBlock> analog_;
  std::unique_ptr<datalogger::ThermocoupleBlock> thermocouples_;
  std::unique_ptr<datalogger::DiagnosticsBlock> diagnostics_;
  std::unique_ptr<datalogger::ProgramBlocks> program_;
  std::array<OdRef, datalogger::kReceivedValues> received_, received_digits_, received_low_, received_high_;
  std::array<OdRef, datalogger::kConstants> constants_;

  std::unique_ptr<Timer> cycle_timer_;
  std::unique_ptr<Timer> conversion_timer_;
  TimePoint power_on_{};
  TimePoint last_inputs_{};
  TimePoint last_program_{};
  Duration inputs_carry_{0};
  Duration program_carry_{0};
  bool idle_ = true;  // the last cycle armed nothing: time since then changed nothing
  std::uint64_t cycles_ = 0;
  std::uint64_t conversions_ = 0;
};

}  // namespace canfleet::devices
