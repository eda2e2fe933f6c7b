#include "node/devices/quad_controller/quad_controller.hpp"

#include "node/devices/eds_dictionary.hpp"
#include "node/devices/quad_controller/quad_error_policy.hpp"
#include "node/devices/quad_controller/quad_objects.hpp"
#include "node/devices/quad_controller/quad_validators.hpp"

namespace canfleet::devices {

QuadController::QuadController(DeviceOptions options)
    : Device(options.ports), options_(std::move(options)), signals_(io_) {}

QuadController::~QuadController() = default;

void QuadController::Build(std::size_t port, canopen::ObjectDictionary& od) {
  (void)port;
  od = LoadVariantDictionary(QuadControllerEdsText(), "quad-controller.eds", options_.eds);
  od_ = &od;
}

void QuadController::ConfigureStack(std::size_t port, StackSetup& setup) {
  (void)port;
  setup.policy = std::make_shared<quad::QuadErrorPolicy>();
  // §3.1.4: at most 16 errors; a cleared error leaves the list at once.
  setup.options.emcy.max_history = 16;
  setup.options.emcy.remove_cleared_from_history = true;
  // §3.1.10: 5555h TRUE boots straight into operational.
  setup.options.start_operational = [this] { return od_->GetUnsigned(quad::kStartInOperational, 0) != 0; };
  setup.hooks.on_reset_application = [this] { OnResetApplication(); };
}

void QuadController::Attach(DeviceContext& context) {
  stack_ = context.stacks.at(0);
  ai_ = std::make_unique<quad::AiBlock>(*stack_, context.scheduler, signals_);
  di_ = std::make_unique<quad::DiBlock>(*stack_, signals_);
  do_ = std::make_unique<quad::DoBlock>(*stack_, context.scheduler, signals_);
  ao_ = std::make_unique<quad::AoBlock>(*stack_, context.scheduler, signals_);
  quad::InstallQuadValidators(*stack_);
  // Process data is not a parameter: a stored output command would drive an output at the next
  // power-on before any master spoke (1010h "save" stores parameters, §3.1.5).
  if (auto* store = stack_->store()) {
    for (std::uint16_t index :
         {quad::kDoWriteState, quad::kAoFieldValue, quad::kReceivedPv, quad::kReceivedPvStatus})
      store->Exclude(index);
  }
  // Appendix A, Table 1.0: for a disabled input "no CAN messages associated with that channel are
  // sent". A TPDO that carries only disabled channels' values (7100h/7130h) stays off the bus; one
  // that also carries anything else is sent (0 in the disabled channel's bytes, README choice 16).
  stack_->pdo().SetTpdoGate([this](std::size_t, std::span<const canopen::MappedObject> entries) {
    if (entries.empty()) return true;
    for (const auto& entry : entries) {
      const bool input_value =
          entry.sub->index == quad::kAiFieldValue || entry.sub->index == quad::kAiProcessValue;
      if (!input_value) return true;
      const auto* mode = stack_->od().Find(quad::kAiOperatingMode, entry.sub->sub_index);
      if (!mode ||
          canopen::DecodeUnsignedLe(mode->value) != static_cast<std::uint8_t>(quad::OperatingMode::kDisabled))
        return true;
    }
    return false;
  });
  // Armed in this order, the 10 ms sample runs before the 1 ms output tick due at the same time.
  sample_tick_ = std::make_unique<PeriodicTick>(context.scheduler, kSamplePeriod, [this] { OnSample(); });
  output_tick_ = std::make_unique<PeriodicTick>(context.scheduler, kOutputPeriod, [this] { OnOutputTick(); });
  sample_tick_->Start();
  output_tick_->Start();
}

void QuadController::OnSample() {
  ai_->Sample();
  di_->Sample(*ai_);
}

void QuadController::OnOutputTick() {
  ai_->CountPulses();
  quad::OutputConditions conditions;
  conditions.nmt = stack_->State();
  conditions.fault_state = stack_->emcy().ActiveCount() > 0;
  conditions.fault_entered = conditions.fault_state && !fault_state_;
  fault_state_ = conditions.fault_state;
  do_->Update(conditions, *ai_, *di_);
  ao_->Update(conditions, *ai_);
}

// §4.2: "Upon reset of the controller, all possible faults ... are in the inactive state." The
// stack has restored the parameters and forgotten its errors; the blocks start over.
void QuadController::OnResetApplication() {
  fault_state_ = false;
  if (ai_) ai_->Reset();
  if (do_) do_->Reset();
  if (ao_) ao_->Reset();
}

}  // namespace canfleet::devices
