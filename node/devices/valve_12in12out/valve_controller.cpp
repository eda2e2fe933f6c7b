#include "node/devices/valve_12in12out/valve_controller.hpp"

#include <algorithm>
#include <optional>

#include "node/devices/eds_dictionary.hpp"
#include "node/devices/family/family_error_policy.hpp"
#include "node/devices/family/input_config.hpp"
#include "node/devices/valve_12in12out/input_block.hpp"
#include "node/devices/valve_12in12out/monitors.hpp"
#include "node/devices/valve_12in12out/output_block.hpp"
#include "node/devices/valve_12in12out/program_blocks.hpp"
#include "node/devices/valve_12in12out/valve_rules.hpp"
#include "node/devices/valve_12in12out/valve_sources.hpp"

namespace canfleet::devices {

namespace {

using namespace std::chrono_literals;
using canopen::Origin;
using canopen::SubObject;

/// The millisecond grid the blocks run on.
TimePoint FloorMs(TimePoint t) {
  return TimePoint(std::chrono::duration_cast<std::chrono::milliseconds>(t.time_since_epoch()));
}

}  // namespace

ValveController::ValveController(DeviceOptions options)
    : Device(options.ports), options_(std::move(options)), signals_(io_) {}

ValveController::~ValveController() {
  if (io_subscription_ != 0) io_.Unsubscribe(io_subscription_);
}

void ValveController::Build(std::size_t port, canopen::ObjectDictionary& od) {
  (void)port;
  od = LoadVariantDictionary(ValveEds(), kEdsFileName, options_.eds);
  od_ = &od;
}

void ValveController::ConfigureStack(std::size_t port, StackSetup& setup) {
  (void)port;
  // §3.2.4 Table 33: description << 24 | channel << 16 | code; 80nn8130h heartbeat, 10008130h life
  // guard, 00008100h RPDO timeout, 00008140h bus-off; 1001h bit 0 only; "a maximum of 4 errors in
  // the list" (the entry declares 5 sub-indexes, README.md).
  const family::ErrorConventions conventions;
  setup.policy = std::make_shared<family::FamilyErrorPolicy>(conventions);
  family::ApplyConventions(conventions, setup.options);
  // §3.4.109: 5555h TRUE starts in operational without a master.
  setup.options.start_operational = [this] { return od_->GetUnsigned(valve::kStartOperational, 0) != 0; };
  setup.hooks.on_reset_application = [this] { OnResetApplication(); };
  // §3.4.110: 5B50h "Change Baud Rate" (Table 32 indexes); the port runs at its stored value from
  // the next reset (README).
  setup.options.bit_rate_object = canopen::BitRateObject{valve::kChangeBaudRate, 0};
  setup.hooks.on_state_changed = [this](canopen::NmtState) { RequestRun(); };
  setup.hooks.on_comm_error = [this](const canopen::CommError& error, bool active) {
    OnCommError(error, active);
  };
}

void ValveController::Attach(DeviceContext& context) {
  using namespace valve;
  stack_ = context.stacks.at(0);
  scheduler_ = &context.scheduler;
  canopen::ObjectDictionary& od = stack_->od();
  rules_ = std::make_unique<ValveRules>(*stack_);
  sources_ = std::make_unique<ValveSources>(od);
  inputs_ = std::make_unique<InputBlock>(*stack_, context.scheduler, signals_);
  program_ = std::make_unique<ProgramBlocks>(od, *sources_);
  outputs_ = std::make_unique<OutputBlock>(*stack_, context.scheduler, signals_, *sources_);
  monitors_ = std::make_unique<Monitors>(*stack_, context.scheduler, signals_);
  sources_->Connect(inputs_.get(), program_.get());
  timer_ = std::make_unique<Timer>(context.scheduler, [this] { Run(); });

  // Received process data is not a parameter: a stored command would drive an output at the next
  // power-on before any master spoke (1010h stores parameters, §3.2.7).
  if (auto* store = stack_->store()) {
    for (std::uint16_t index : {kAoProcessValue, kDoWriteState, kExtraPv})
      store->Exclude(index);
  }
  // §4: a disabled input sends "no CAN messages associated with that channel": a TPDO carrying only
  // input values of disabled channels stays off the bus.
  stack_->pdo().SetTpdoGate([this](std::size_t, std::span<const canopen::MappedObject> entries) {
    if (entries.empty()) return true;
    for (const auto& entry : entries) {
      const bool input_value = entry.sub->index == kAiFieldValue || entry.sub->index == kAiProcessValue;
      if (!input_value) return true;
      if (od_->GetUnsigned(kAiMode, entry.sub->sub_index) != static_cast<std::uint64_t>(InputMode::kOff))
        return true;
    }
    return false;
  });
  // Events that can change what the blocks compute: a simulated input, an application object
  // written by SDO or RPDO (the device's own writes do not count), the NMT state (ConfigureStack).
  io_subscription_ = io_.Subscribe([this](const IoSignal& signal) {
    if (signal.direction() == IoDirection::kInput) RequestRun();
  });
  // One listener for the dictionary rather than one per application sub-object (2400 of them,
  // ~130 bytes each of idle RSS).
  od.AddWriteListener([this](SubObject& sub, Origin origin) {
    if (origin != Origin::kDevice && sub.index >= 0x2000 && sub.index <= 0x7FFF) RequestRun();
  });
  io_.SetIgnoredHook([this](const IoSignal& input) { return IgnoredInput(input); });
  last_run_ = FloorMs(context.scheduler.Now());
  RequestRun();
}

std::string ValveController::IgnoredInput(const IoSignal& input) const {
  using namespace valve;
  // §2.1 Tables 4 and 5: the family's rule (6112h, 6110h), family/input_config.hpp.
  for (int ch = 0; ch < kInputs; ++ch) {
    const auto sub = static_cast<std::uint8_t>(ch + 1);
    family::InputPin pin{.channel = "IN" + std::to_string(sub),
                         .sub = sub,
                         .sensor_type = static_cast<std::int64_t>(od_->GetUnsigned(kAiSensorType, sub)),
                         .mode = static_cast<std::int64_t>(od_->GetUnsigned(kAiMode, sub)),
                         .voltage = signals_.voltage[ch],
                         .current = signals_.current[ch],
                         .resistance = signals_.resistance[ch],
                         .frequency = signals_.frequency[ch],
                         .duty = signals_.duty[ch],
                         .level = signals_.level[ch]};
    if (pin.Has(input)) return family::IgnoredInput(input, pin);
  }
  for (int ch = 0; ch < kOutputs; ++ch) {
    if (&input != signals_.load_current[ch]) continue;
    // §1.4 Table 14: only an on/off output (6310h = 1000) passes the load's own current.
    const auto sub = static_cast<std::uint8_t>(ch + 1);
    const auto type = od_->GetUnsigned(kAoType, sub);
    if (type == static_cast<std::uint64_t>(OutputType::kDigital)) return {};
    return IgnoredNotice(input,
                         "OUT" + std::to_string(sub) + "'s configuration (6310h sub " + std::to_string(sub) +
                             " = " + std::to_string(type) + ")",
                         "6310h sub " + std::to_string(sub) + " = 1000 reads it");
  }
  return {};
}

bool ValveController::Idle() const {
  return !timer_ || !timer_->Armed();
}

void ValveController::RequestRun() {
  if (!timer_) return;
  const TimePoint next = FloorMs(scheduler_->Now()) + 1ms;
  if (!timer_->Armed() || timer_->Deadline() > next) timer_->StartAt(next);
}

void ValveController::Run() {
  const TimePoint now = FloorMs(scheduler_->Now());
  const auto elapsed = std::max(std::chrono::milliseconds(1),
                                std::chrono::duration_cast<std::chrono::milliseconds>(now - last_run_));
  last_run_ = now;
  ++runs_;

  monitors_->Run();
  inputs_->Run(elapsed);
  bool changed = program_->Run(elapsed);
  valve::OutputConditions conditions;
  // Choice (README.md): the application keeps running in pre-operational (stand-alone logic,
  // §1.10), a stopped node drives nothing.
  conditions.stopped = stack_->State() == canopen::NmtState::kStopped;
  conditions.supply_fault = monitors_->SupplyFault();
  changed |= outputs_->Run(now, elapsed, conditions);

  std::optional<std::chrono::milliseconds> wake;
  const auto earliest = [&wake](std::optional<std::chrono::milliseconds> t) {
    if (t) wake = wake ? std::min(*wake, *t) : *t;
  };
  earliest(inputs_->NextWake());
  earliest(program_->NextWake());
  earliest(outputs_->NextWake(now));
  if (changed) earliest(1ms);
  if (!wake) return;
  const TimePoint next = now + std::max(*wake, std::chrono::milliseconds(1));
  if (!timer_->Armed() || timer_->Deadline() > next) timer_->StartAt(next);
}

// The stack restored the parameters and forgot its errors (§3.2.4: faults are conditions; a
// reset starts without any): every block starts over.
void ValveController::OnResetApplication() {
  if (!timer_) return;
  rules_->Resync();
  sources_->ClearRpdoTimeouts();
  inputs_->Reset();
  program_->Reset();
  outputs_->Reset();
  monitors_->Reset();
  RequestRun();
}

void ValveController::OnCommError(const canopen::CommError& error, bool active) {
  if (!sources_) return;
  if (error.kind == canopen::CommErrorKind::kRpdoTimeout) sources_->SetRpdoTimeout(error.detail, active);
  RequestRun();
}

}  // namespace canfleet::devices
