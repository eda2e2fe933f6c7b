#pragma once
/// @file The Axiomatic High Temperature Quadrature Encoder Input Dual Proportional Valve Controller
/// AX023241 (user manual v1.1; CiA DS-404 based): two inputs reading a quadrature encoder (or each a
/// frequency, PWM or digital input), two proportional valve drives, one PID, two lookup tables and
/// two math blocks wired by (source, number), supply and temperature fault detection, and the
/// start-up modes of 5555h. Its dictionary is encoder-dual-valve.od (this folder); README.md lists
/// the manual's contradictions and the choices made.
///
/// Time is events (design decision 10): the blocks are evaluated together (inputs -> supply ->
/// math -> lookup tables -> PID -> outputs, the family's order, blocks/signal.hpp) one millisecond
/// after anything changes (a simulated input, an SDO/PDO write of an application object, an NMT
/// state change, an RPDO timeout), then every millisecond only while something is in progress (a
/// filter settling, a ramp, a PID loop that has not settled, a consumed count that moves) or at
/// the single instant something is due (a fault delay, a hotshot phase, a digital delay, a
/// short-circuit retry). A node with steady inputs does not wake.

#include <cstdint>
#include <memory>
#include <string_view>

#include "node/devices/device.hpp"
#include "node/devices/embedded_eds.hpp"
#include "node/devices/encoder_dual_valve/encoder_io.hpp"

namespace canfleet::devices {

/// encoder-dual-valve.eds, generated from encoder-dual-valve.od by the build and compiled in deflated.
EmbeddedEds EncoderEds();

namespace encoder {
class EncoderSources;
class PulseInputs;
class SupplyMonitor;
class FunctionBlocks;
class ValveOutputs;
class StartupMode;
}  // namespace encoder

class EncoderValveController final : public Device {
 public:
  static constexpr std::string_view kName = "encoder-dual-valve";
  static constexpr std::string_view kSummary =
      "Axiomatic quadrature encoder input dual valve controller AX023241 (CiA 404): 2 QD/FIN/DIN, 2 valve "
      "outputs";
  static constexpr std::uint8_t kFactoryNodeId = 127;        // C3-1.1
  static constexpr std::uint32_t kFactoryBitRateKbit = 125;  // C3-1.1, Table 16
  static constexpr std::uint8_t kErrorHistoryDepth = 15;     // C3-1.2.4

  explicit EncoderValveController(DeviceOptions options = {});
  ~EncoderValveController() override;

  std::string_view Name() const override { return kName; }
  void Build(std::size_t port, canopen::ObjectDictionary& od) override;
  void ConfigureStack(std::size_t port, StackSetup& setup) override;
  void Attach(DeviceContext& context) override;

  /// Evaluations run since the node was built (tests: a steady node does not evaluate).
  std::uint64_t Evaluations() const { return evaluations_; }
  /// An evaluation is scheduled.
  bool Ticking() const;

 private:
  using Ms = std::chrono::milliseconds;
  void Wake();
  void OnTick();
  void Evaluate(TimePoint now, Ms elapsed);
  void Schedule();
  void OnResetApplication();
  void OnStateChanged(canopen::NmtState state);
  void OnCommError(const canopen::CommError& error, bool active);
  void InstallWakeListeners();

  DeviceOptions options_;
  encoder::EncoderIo signals_;
  canopen::ObjectDictionary* od_ = nullptr;
  canopen::CanopenStack* stack_ = nullptr;
  Scheduler* scheduler_ = nullptr;
  std::unique_ptr<encoder::EncoderSources> sources_;
  std::unique_ptr<encoder::PulseInputs> inputs_;
  std::unique_ptr<encoder::SupplyMonitor> supply_;
  std::unique_ptr<encoder::FunctionBlocks> blocks_;
  std::unique_ptr<encoder::ValveOutputs> outputs_;
  std::unique_ptr<encoder::StartupMode> startup_;
  std::unique_ptr<Timer> tick_;
  TimePoint last_eval_{};
  bool evaluating_ = false;
  /// Something changed during an evaluation (an EMCY's 1029h reaction, a listener): evaluate again.
  bool wake_pending_ = false;
  std::uint64_t evaluations_ = 0;
  std::size_t subscription_ = 0;
};

}  // namespace canfleet::devices
