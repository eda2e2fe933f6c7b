#include "node/devices/quad_controller/quad_controller.hpp"

#include "node/devices/eds_dictionary.hpp"
#include "node/devices/family/input_config.hpp"
#include "node/devices/quad_controller/quad_error_policy.hpp"
#include "node/devices/quad_controller/quad_objects.hpp"
#include "node/devices/quad_controller/quad_validators.hpp"
#include "node/devices/wake_on_change.hpp"

namespace canfleet::devices {

QuadController::QuadController(DeviceOptions options)
    : Device(options.ports), options_(std::move(options)), signals_(io_) {}

QuadController::~QuadController() = default;

void QuadController::Build(std::size_t port, canopen::ObjectDictionary& od) {
  (void)port;
  od = LoadVariantDictionary(QuadControllerEds(), "quad-controller.eds", options_.eds);
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
  // §4.2: the outputs follow the NMT state.
  setup.hooks.on_state_changed = [this](canopen::NmtState) { WakeTicks(); };
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
  // Both sleep after a tick that changed nothing, until something they read changes; a frequency
  // input's measuring window keeps both running (it moves every millisecond; the sample reads it).
  sample_tick_ = std::make_unique<PeriodicTick>(
      context.scheduler, kSamplePeriod, [this] { OnSample(); },
      [this] { return !sample_changed_ && !ai_->Counting(); });
  output_tick_ = std::make_unique<PeriodicTick>(
      context.scheduler, kOutputPeriod, [this] { OnOutputTick(); }, [this] { return !output_changed_; });
  WakeOnChanges(*stack_, io_, [this] { WakeTicks(); });
  io_.SetIgnoredHook([this](const IoSignal& input) { return IgnoredInput(input); });
  sample_tick_->Start();
  output_tick_->Start();
}

std::string QuadController::IgnoredInput(const IoSignal& input) const {
  // §3.3.13/§3.3.14: the family's rule (6112h, 6110h), family/input_config.hpp.
  for (int ch = 0; ch < quad::kInputs; ++ch) {
    const bool analog = ch < quad::kAnalogInputs;
    const std::size_t f = static_cast<std::size_t>(ch - quad::kAnalogInputs);
    family::InputPin pin{.channel = "IN" + std::to_string(quad::SubOf(ch)),
                         .sub = quad::SubOf(ch),
                         .sensor_type = static_cast<std::int64_t>(ai_->Type(ch)),
                         .mode = static_cast<std::int64_t>(ai_->Mode(ch)),
                         .voltage = analog ? signals_.ain_voltage[ch] : nullptr,
                         .current = analog ? signals_.ain_current[ch] : nullptr,
                         .frequency = analog ? nullptr : signals_.fin_frequency[f],
                         .duty = analog ? nullptr : signals_.fin_duty[f],
                         .level = signals_.din_level[ch]};
    if (pin.Has(input)) return family::IgnoredInput(input, pin);
  }
  for (int o = 0; o < quad::kPouts; ++o) {
    if (&input != signals_.pout_load_current[o]) continue;
    // §3.5.15: only a digital output (6310h = 1000) passes the load's own current.
    const auto* type = stack_->od().Find(quad::kAoOutputType, quad::SubOf(o));
    const auto value = type ? canopen::DecodeUnsignedLe(type->value) : 0;
    if (value == static_cast<std::uint64_t>(quad::OutputType::kDigital)) return {};
    const std::string sub = std::to_string(quad::SubOf(o));
    return IgnoredNotice(
        input, "OUT" + sub + "'s configuration (6310h sub " + sub + " = " + std::to_string(value) + ")",
        "6310h sub " + sub + " = 1000 reads it");
  }
  return {};
}

void QuadController::OnSample() {
  const bool ai_changed = ai_->Sample();
  const bool di_changed = di_->Sample(*ai_);
  sample_changed_ = ai_changed || di_changed;
  // The output stage reads what the sample produced (field values, ON/OFF states, 6000h).
  if (sample_changed_) output_tick_->Wake();
}

void QuadController::OnOutputTick() {
  const bool pulses_changed = ai_->CountPulses();
  quad::OutputConditions conditions;
  conditions.nmt = stack_->State();
  conditions.fault_state = stack_->emcy().ActiveCount() > 0;
  conditions.fault_entered = conditions.fault_state && !fault_state_;
  const bool fault_changed = fault_state_ != conditions.fault_state;
  fault_state_ = conditions.fault_state;
  const bool do_changed = do_->Update(conditions, *ai_, *di_);
  const bool ao_changed = ao_->Update(conditions, *ai_);
  output_changed_ = pulses_changed || fault_changed || do_changed || ao_changed;
}

void QuadController::WakeTicks() {
  if (sample_tick_) sample_tick_->Wake();
  if (output_tick_) output_tick_->Wake();
}

// §4.2: "Upon reset of the controller, all possible faults ... are in the inactive state." The
// stack has restored the parameters and forgotten its errors; the blocks start over.
void QuadController::OnResetApplication() {
  fault_state_ = false;
  if (ai_) ai_->Reset();
  if (do_) do_->Reset();
  if (ao_) ao_->Reset();
  WakeTicks();
}

}  // namespace canfleet::devices
