#include "node/devices/encoder_dual_valve/encoder_valve_controller.hpp"

#include <algorithm>
#include <array>
#include <optional>

#include "node/devices/eds_dictionary.hpp"
#include "node/devices/encoder_dual_valve/encoder_sources.hpp"
#include "node/devices/encoder_dual_valve/encoder_validators.hpp"
#include "node/devices/encoder_dual_valve/function_blocks.hpp"
#include "node/devices/encoder_dual_valve/pulse_inputs.hpp"
#include "node/devices/encoder_dual_valve/startup_mode.hpp"
#include "node/devices/encoder_dual_valve/supply_monitor.hpp"
#include "node/devices/encoder_dual_valve/valve_outputs.hpp"
#include "node/devices/family/family_error_policy.hpp"

namespace canfleet::devices {

using canopen::NmtState;
using canopen::Origin;
using namespace encoder;

namespace {

constexpr std::chrono::milliseconds kTick{1};

std::optional<std::chrono::milliseconds> Earliest(std::optional<std::chrono::milliseconds> a,
                                                  std::optional<std::chrono::milliseconds> b) {
  if (!a) return b;
  if (!b) return a;
  return std::min(*a, *b);
}

}  // namespace

EncoderValveController::EncoderValveController(DeviceOptions options)
    : Device(options.ports), options_(std::move(options)), signals_(io_) {}

EncoderValveController::~EncoderValveController() {
  if (subscription_ != 0) io_.Unsubscribe(subscription_);
}

void EncoderValveController::Build(std::size_t port, canopen::ObjectDictionary& od) {
  (void)port;
  od = LoadVariantDictionary(EncoderEds(), "encoder-dual-valve.eds", options_.eds);
  od_ = &od;
}

void EncoderValveController::ConfigureStack(std::size_t port, StackSetup& setup) {
  (void)port;
  // No EMCY table in the manual: the family's conventions (README.md "EMCY codes") with the 15
  // entries C3-1.2.4 declares.
  family::ErrorConventions conventions;
  conventions.history_depth = kErrorHistoryDepth;
  setup.policy = std::make_shared<family::FamilyErrorPolicy>(conventions);
  family::ApplyConventions(conventions, setup.options);
  setup.options.start_operational = [this] { return StartupMode::StartOperational(*od_); };
  setup.hooks.on_reset_application = [this] { OnResetApplication(); };
  setup.hooks.on_state_changed = [this](NmtState state) { OnStateChanged(state); };
  setup.hooks.on_comm_error = [this](const canopen::CommError& error, bool active) {
    OnCommError(error, active);
  };
}

void EncoderValveController::Attach(DeviceContext& context) {
  stack_ = context.stacks.at(0);
  scheduler_ = &context.scheduler;
  canopen::ObjectDictionary& od = stack_->od();
  sources_ = std::make_unique<EncoderSources>(od);
  inputs_ = std::make_unique<PulseInputs>(*stack_, context.scheduler, signals_);
  supply_ = std::make_unique<SupplyMonitor>(*stack_, context.scheduler, signals_);
  blocks_ = std::make_unique<FunctionBlocks>(od);
  outputs_ = std::make_unique<ValveOutputs>(*stack_, context.scheduler, signals_);
  startup_ = std::make_unique<StartupMode>(context.scheduler, od, *context.ports.at(0));
  sources_->SetProviders(inputs_.get(), outputs_.get(), blocks_.get());
  tick_ = std::make_unique<Timer>(context.scheduler, [this] { OnTick(); });

  InstallEncoderValidators(*stack_, sources_->sources(),
                           [this](int) { inputs_->ZeroCounter(scheduler_->Now()); });
  // Process data is not a parameter: a stored command would drive an output at the next power-on
  // before any master spoke (1010h stores parameters).
  if (auto* store = stack_->store()) {
    for (std::uint16_t index : {kAoProcessValue, kAoFieldValue, kEcValue, kDoWriteState})
      store->Exclude(index);
  }
  // A moving count is sampled when a client reads it (SDO upload, TPDO).
  for (int ch = 0; ch < kInputs; ++ch) {
    for (std::uint16_t index : {kAiFieldValue, kAiProcessValue}) {
      OdRef(od, index, SubOf(ch)).sub().AddReadHook([this, ch](canopen::SubObject&, Origin) {
        inputs_->SampleOnRead(ch, scheduler_->Now());
        return canopen::SdoAbort::kNone;
      });
    }
  }
  InstallWakeListeners();
  io_.SetIgnoredHook([this](const IoSignal& input) { return inputs_->IgnoredInput(input); });
  subscription_ = io_.Subscribe([this](const IoSignal& signal) {
    if (signal.direction() != IoDirection::kInput) return;
    inputs_->OnSignal(signal, scheduler_->Now());
    Wake();
  });
}

// Any network write (SDO, RPDO) of an application object may change what the blocks do.
void EncoderValveController::InstallWakeListeners() {
  auto& objects = stack_->od().objects();
  for (auto it = objects.lower_bound(0x2000); it != objects.end() && it->first <= 0x7FFF; ++it) {
    for (auto& [sub_index, sub] : it->second.subs) {
      (void)sub_index;
      sub.AddListener([this](canopen::SubObject&, Origin origin) {
        if (origin != Origin::kDevice) Wake();
      });
    }
  }
}

bool EncoderValveController::Ticking() const {
  return tick_ && tick_->Armed();
}

void EncoderValveController::Wake() {
  if (!tick_) return;
  if (evaluating_) {
    wake_pending_ = true;
    return;
  }
  const TimePoint now = scheduler_->Now();
  if (!tick_->Armed()) {
    last_eval_ = now;  // idle until now: nothing was in progress, no time to account for
    tick_->StartAt(now + kTick);
  } else if (tick_->Deadline() > now + kTick) {
    tick_->StartAt(now + kTick);
  }
}

void EncoderValveController::OnTick() {
  const TimePoint now = scheduler_->Now();
  const auto elapsed = std::chrono::duration_cast<Ms>(now - last_eval_);
  last_eval_ += elapsed;
  evaluating_ = true;
  Evaluate(now, elapsed);
  evaluating_ = false;
  Schedule();
}

void EncoderValveController::Evaluate(TimePoint now, Ms elapsed) {
  ++evaluations_;
  const blocks::ControlSources& sources = sources_->sources();
  inputs_->Update(now, elapsed);
  supply_->Update(elapsed);
  blocks_->UpdateMath(sources);
  blocks_->UpdateLookupTables(sources);
  blocks_->UpdatePid(elapsed, sources);
  OutputConditions conditions;
  conditions.nmt = stack_->State();
  conditions.all_off = supply_->OutputsOff();
  outputs_->Update(elapsed, conditions, sources);
  io_.Publish(*signals_.shaft_counts, static_cast<double>(inputs_->shaft().EdgesAt(now)));
}

void EncoderValveController::Schedule() {
  std::array<bool, kInputs> consumed{};
  for (int ch = 0; ch < kInputs; ++ch)
    consumed[ch] = sources_->Wired(blocks::SourceKind::kAnalogInput, SubOf(ch));
  std::optional<Ms> next = inputs_->NextChange(consumed);
  next = Earliest(next, supply_->NextChange());
  next = Earliest(next, blocks_->NextChange());
  next = Earliest(next, outputs_->NextChange());
  if (wake_pending_) next = Earliest(next, kTick);
  wake_pending_ = false;
  if (next)
    tick_->StartAt(last_eval_ + std::max(*next, kTick));
  else
    tick_->Cancel();
}

// Power-on and NMT reset node: the stack restored the parameters and forgot its errors; the blocks
// start over and are evaluated one millisecond later.
void EncoderValveController::OnResetApplication() {
  if (!tick_) return;
  const TimePoint now = scheduler_->Now();
  inputs_->Reset(now);
  supply_->Reset();
  blocks_->Reset();
  outputs_->Reset();
  for (std::uint8_t rpdo = 1; rpdo <= 4; ++rpdo)
    sources_->SetRpdoTimeout(rpdo, false);
  tick_->Cancel();
  Wake();
}

void EncoderValveController::OnStateChanged(NmtState state) {
  if (startup_) startup_->OnStateChanged(state);
  Wake();
}

void EncoderValveController::OnCommError(const canopen::CommError& error, bool active) {
  if (error.kind != canopen::CommErrorKind::kRpdoTimeout || !sources_) return;
  sources_->SetRpdoTimeout(error.detail, active);
  Wake();
}

}  // namespace canfleet::devices
