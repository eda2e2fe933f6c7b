#pragma once
/// @file The Axiomatic CANopen Quad Controller AX020506 (user manual V2.02; CiA DS-404 device):
/// 4 analog inputs AIN1-4, 2 pulse inputs FIN1-2, 4 proportional outputs POUT1-4 and one digital
/// output DOUT, any input able to drive any output. Its dictionary is quad-controller.eds (this
/// folder); its behaviour is the DI, AI, DO and AO blocks (one file each), the fault handling of
/// §4 (delayed_fault.hpp, load_faults.hpp, quad_error_policy.hpp) and the NMT rules of §4.2.
/// README.md in this folder lists where the manual contradicts itself and what was chosen.
///
/// Timing: inputs are sampled every 10 ms (§2.3, Appendix A); the output stage (ramps, frequency
/// counting, fault reactions) runs every 1 ms. Both ticks run on demand (periodic_tick.hpp): with
/// steady inputs and nothing in progress they sleep, and an input set, an object written, an NMT
/// state change or an error raised or cleared wakes them at their next instant on the 10 ms / 1 ms
/// grid, so the outputs change at exactly the instants they would with fixed ticks.

#include <memory>
#include <string_view>

#include "node/devices/device.hpp"
#include "node/devices/embedded_eds.hpp"
#include "node/devices/periodic_tick.hpp"
#include "node/devices/quad_controller/ai_block.hpp"
#include "node/devices/quad_controller/ao_block.hpp"
#include "node/devices/quad_controller/di_block.hpp"
#include "node/devices/quad_controller/do_block.hpp"
#include "node/devices/quad_controller/quad_io.hpp"

namespace canfleet::devices {

/// quad-controller.eds, generated from quad-controller.od by the build and compiled in deflated.
EmbeddedEds QuadControllerEds();

class QuadController final : public Device {
 public:
  static constexpr std::string_view kName = "quad-controller";
  static constexpr std::string_view kSummary =
      "Axiomatic CANopen Quad Controller AX020506 (CiA 404): 4 AIN, 2 FIN, 4 POUT, 1 DOUT";
  static constexpr Duration kSamplePeriod = std::chrono::milliseconds(10);
  static constexpr Duration kOutputPeriod = std::chrono::milliseconds(1);

  explicit QuadController(DeviceOptions options = {});
  ~QuadController() override;

  std::string_view Name() const override { return kName; }
  void Build(std::size_t port, canopen::ObjectDictionary& od) override;
  void ConfigureStack(std::size_t port, StackSetup& setup) override;
  void Attach(DeviceContext& context) override;

  /// The controller fault state of §4.2: at least one active error.
  bool FaultState() const { return fault_state_; }

 private:
  void OnSample();
  void OnOutputTick();
  void OnResetApplication();
  void WakeTicks();
  /// The simulated I/O's ignored hook: why the present 6110h/6112h/6310h do not read `input`.
  std::string IgnoredInput(const IoSignal& input) const;

  DeviceOptions options_;
  quad::QuadIo signals_;
  canopen::ObjectDictionary* od_ = nullptr;
  canopen::CanopenStack* stack_ = nullptr;
  std::unique_ptr<quad::AiBlock> ai_;
  std::unique_ptr<quad::DiBlock> di_;
  std::unique_ptr<quad::DoBlock> do_;
  std::unique_ptr<quad::AoBlock> ao_;
  std::unique_ptr<PeriodicTick> sample_tick_;
  std::unique_ptr<PeriodicTick> output_tick_;
  bool fault_state_ = false;
  /// The last tick changed the blocks' state: the next one may change more (on-demand ticks).
  bool sample_changed_ = false;
  bool output_changed_ = false;
};

}  // namespace canfleet::devices
