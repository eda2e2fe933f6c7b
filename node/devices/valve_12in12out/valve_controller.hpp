#pragma once
/// @file The Axiomatic CANopen 12 Input 12 Output Valve Controller AX020411A (user manual
/// UMAX020411A V1.0.2; CiA DS-404): 7 universal inputs, 5 digital/PWM inputs, 8 proportional
/// outputs, 4 digital outputs, 4 PID loops, 12 lookup tables, 4 logic blocks, 6 math blocks, supply
/// and processor-temperature monitoring. Its dictionary is valve-12in12out.od (this folder); the
/// behaviour is InputBlock, ProgramBlocks, OutputBlock and Monitors wired by ValveSources, with the
/// SDO rules and 5550h cascades of ValveRules and the family's error conventions
/// (family::FamilyErrorPolicy). README.md lists the manual's contradictions and the choices made.
///
/// Time is events (design decision 10): the blocks run on a one-millisecond grid, but only when
/// something asks for a run: a simulated input changed, an SDO or RPDO wrote an application object,
/// the NMT state or a communication error changed, or a block has something in progress (a filter
/// settling, a fault delay, a ramp, a blink, a delay, a hotshot, a feedback window, a PID cycle, a
/// time-response table). A node whose inputs are steady arms no timer of its own.
///
/// One run (README.md "evaluation order"): supply/temperature -> inputs -> math -> lookup tables ->
/// logic -> PID -> outputs. A block reading a later one sees its previous run; when any block
/// output changed, one more run follows a millisecond later.

#include <chrono>
#include <cstdint>
#include <memory>
#include <string_view>

#include "node/devices/device.hpp"
#include "node/devices/embedded_eds.hpp"
#include "node/devices/valve_12in12out/valve_io.hpp"

namespace canfleet::devices {

/// valve-12in12out.eds, generated from valve-12in12out.od by the build and compiled in deflated.
EmbeddedEds ValveEds();

namespace valve {
class InputBlock;
class ProgramBlocks;
class OutputBlock;
class Monitors;
class ValveRules;
class ValveSources;
}  // namespace valve

class ValveController final : public Device {
 public:
  static constexpr std::string_view kName = "valve-12in12out";
  static constexpr std::string_view kSummary =
      "Axiomatic 12 Input 12 Output Valve Controller AX020411A (CiA 404): 7 UI, 5 DI, 8 OUT, 4 DO";
  /// §3.1: "factory programmed with a Node ID = 127 (0x7F) and with Baudrate = 125 kbps".
  static constexpr std::uint8_t kFactoryNodeId = 127;
  static constexpr std::uint32_t kFactoryBitRateKbit = 125;
  static constexpr std::string_view kEdsFileName = "valve-12in12out.eds";

  explicit ValveController(DeviceOptions options = {});
  ~ValveController() override;

  std::string_view Name() const override { return kName; }
  void Build(std::size_t port, canopen::ObjectDictionary& od) override;
  void ConfigureStack(std::size_t port, StackSetup& setup) override;
  void Attach(DeviceContext& context) override;

  /// No run is pending: the node sleeps until an event (tests of "time is events").
  bool Idle() const;
  /// Runs since construction.
  std::uint64_t Runs() const { return runs_; }

 private:
  void RequestRun();
  void Run();
  void OnResetApplication();
  void OnCommError(const canopen::CommError& error, bool active);
  /// The simulated I/O's ignored hook: why the present 6110h/6112h/6310h do not read `input`.
  std::string IgnoredInput(const IoSignal& input) const;

  DeviceOptions options_;
  valve::ValveIo signals_;
  canopen::ObjectDictionary* od_ = nullptr;
  canopen::CanopenStack* stack_ = nullptr;
  Scheduler* scheduler_ = nullptr;
  std::unique_ptr<valve::ValveRules> rules_;
  std::unique_ptr<valve::ValveSources> sources_;
  std::unique_ptr<valve::InputBlock> inputs_;
  std::unique_ptr<valve::ProgramBlocks> program_;
  std::unique_ptr<valve::OutputBlock> outputs_;
  std::unique_ptr<valve::Monitors> monitors_;
  std::unique_ptr<Timer> timer_;
  TimePoint last_run_{};
  std::uint64_t runs_ = 0;
  std::size_t io_subscription_ = 0;
};

}  // namespace canfleet::devices
