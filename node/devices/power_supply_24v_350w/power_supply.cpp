#include "node/devices/power_supply_24v_350w/power_supply.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "node/devices/eds_dictionary.hpp"
#include "node/devices/family/family_error_policy.hpp"
#include "node/devices/power_supply_24v_350w/ps_objects.hpp"
#include "node/devices/power_supply_24v_350w/ps_validators.hpp"
#include "node/devices/wake_on_change.hpp"

namespace canfleet::devices {

using canopen::Origin;
using std::chrono::milliseconds;

namespace {

std::int64_t Round(double value) {
  return std::llround(value);
}

/// V and A to the signals' mV and mA, at the objects' resolution (§1.2.3).
double Milli(double value) {
  return std::round(value * 1000.0);
}

std::uint32_t Flag(bool on, unsigned shift) {
  return (on ? ps::kFlagOn : ps::kFlagOff) << shift;
}

}  // namespace

PowerSupply::PowerSupply(DeviceOptions options)
    : Device(options.ports), options_(std::move(options)), signals_(io_) {}

PowerSupply::~PowerSupply() {
  io_.Unsubscribe(io_subscription_);
  if (port_) {
    port_->ObserveFrames(nullptr);
    port_->SetMuted(false);
  }
}

void PowerSupply::DeclareSignals(SimulatedIo& io) {
  ps::PsIo declared(io);
}

void PowerSupply::Build(std::size_t port, canopen::ObjectDictionary& od) {
  (void)port;
  od = LoadVariantDictionary(PowerSupplyEds(), kEdsFileName, options_.eds);
  od_ = &od;
}

void PowerSupply::ConfigureStack(std::size_t port, StackSetup& setup) {
  (void)port;
  // Table 9 (§2.2.4): the family's encoding (80nn8130h, 10008130h, 00008100h, 00008140h), 1029h
  // sub 1 for every communication error, 1003h keeps 4 entries and drops cleared ones.
  const family::ErrorConventions conventions;
  setup.policy = std::make_shared<family::FamilyErrorPolicy>(conventions);
  family::ApplyConventions(conventions, setup.options);
  // §2.4.17: 5555h TRUE boots straight into operational.
  setup.options.start_operational = [this] { return od_->GetUnsigned(ps::kStartInOperational, 0) != 0; };
  setup.hooks.on_reset_application = [this] { OnResetApplication(); };
  // §2.4 table: 5B50h "Change Baud Rate" (Table 8 indexes); the port runs at its stored value from
  // the next reset (README).
  setup.options.bit_rate_object = canopen::BitRateObject{ps::kChangeBaudRate, 0};
  // §1.2.2: sleep is never allowed in operational; a state change may allow or end it.
  setup.hooks.on_state_changed = [this](canopen::NmtState) { RequestStep(); };
}

void PowerSupply::Attach(DeviceContext& context) {
  stack_ = context.stacks.at(0);
  port_ = context.ports.at(0);
  scheduler_ = &context.scheduler;
  auto& od = stack_->od();
  using namespace ps;
  io_.SetIgnoredHook([this](const IoSignal& input) { return signals_.IgnoredInput(input); });

  filter_type_ = OdRef(od, kInputFilterType, 1);
  filter_constant_ = OdRef(od, kInputFilterConstant, 1);
  input_actual_ = OdRef(od, kInputActual, 1);
  temperature_ = OdRef(od, kTemperature, 0);
  output_voltage_ = OdRef(od, kOutputActual, 1);
  output_current_ = OdRef(od, kOutputActual, 2);
  set_voltage_ = OdRef(od, kOutputSetValues, kSetVoltage);
  max_voltage_ = OdRef(od, kOutputSetValues, kMaxVoltage);
  min_voltage_ = OdRef(od, kOutputSetValues, kMinVoltage);
  range_voltage_ = OdRef(od, kOutputRanges, 1);
  set_current_ = OdRef(od, kOutputSetValues, kSetCurrent);
  max_current_ = OdRef(od, kOutputSetValues, kMaxCurrent);
  range_current_ = OdRef(od, kOutputRanges, 3);
  limit_control_ = OdRef(od, kCurrentLimitControl, 0);
  input_delay_ = OdRef(od, kDeviceStatusDelay, 1);
  output_delay_ = OdRef(od, kDeviceStatusDelay, 2);
  sleep_delay_ = OdRef(od, kSleepDelay, 0);
  device_status_word_ = OdRef(od, kDeviceStatus, 1);
  output_status_word_ = OdRef(od, kOutputStatus, 1);

  control_ = std::make_unique<OutputControl>(*stack_);

  // §2.3.9: Vt1/Vt2 against 6114h/611Ah and 6115h/611Bh (mV), delays 6119h.1/.2; Tt1/Tt2 against
  // 6021h/6025h and 6022h/6026h (0.1 degC), delays 6119h.9/.10.
  input_status_ = std::make_unique<FailureStatus>(od, kInputFailure);
  input_status_->AddFlag(kFlagVt1, OdRef(od, kInputThreshold1, 1), OdRef(od, kInputReturn1, 1),
                         OdRef(od, kInputFailureDelay, 1));
  input_status_->AddFlag(kFlagVt2, OdRef(od, kInputThreshold2, 1), OdRef(od, kInputReturn2, 1),
                         OdRef(od, kInputFailureDelay, 2));
  input_status_->AddFlag(kFlagTt1, OdRef(od, kTemperatureThreshold1, 0), OdRef(od, kTemperatureReturn1, 0),
                         OdRef(od, kInputFailureDelay, 9));
  input_status_->AddFlag(kFlagTt2, OdRef(od, kTemperatureThreshold2, 0), OdRef(od, kTemperatureReturn2, 0),
                         OdRef(od, kInputFailureDelay, 10));
  // §2.3.17, Table 5: voltage and current thresholds/returns/delays in 6205h.
  output_status_ = std::make_unique<FailureStatus>(od, kOutputFailure);
  const auto set = [&od](std::uint8_t sub) { return OdRef(od, kOutputSetValues, sub); };
  output_status_->AddFlag(kFlagVt1, set(kVoltageThreshold1), set(kVoltageReturn1), set(kVoltageDelay1));
  output_status_->AddFlag(kFlagVt2, set(kVoltageThreshold2), set(kVoltageReturn2), set(kVoltageDelay2));
  output_status_->AddFlag(kFlagCt1, set(kCurrentThreshold1), set(kCurrentReturn1), set(kCurrentDelay1));
  output_status_->AddFlag(kFlagCt2, set(kCurrentThreshold2), set(kCurrentReturn2), set(kCurrentDelay2));
  // §2.3.2: the device's input (i) and output (o1) failure flags, delays 6013h.1/.2 (§2.3.3).
  device_status_ = std::make_unique<FailureStatus>(od, kDeviceFailure);
  device_status_->AddFlag(kFlagInput, OdRef(), OdRef(), input_delay_);
  device_status_->AddFlag(kFlagOutput, OdRef(), OdRef(), output_delay_);
  // Table 9: one FF04h and one FF06h entry, whichever flags caused them; 1029h sub 3 / sub 4.
  input_failure_ = std::make_unique<DelayedFault>(
      *scheduler_, *stack_, family::MakeFamilyEntry(kEmcyInputFailure, 0, 0), kBehaviourInput);
  output_failure_ = std::make_unique<DelayedFault>(
      *scheduler_, *stack_, family::MakeFamilyEntry(kEmcyOutputFailure, 0, 0), kBehaviourOutput);

  sleep_ = std::make_unique<SleepMode>(*scheduler_, *port_, [this](bool asleep) { OnSleepChange(asleep); });
  tick_ = std::make_unique<PeriodicTick>(
      *scheduler_, kLoopPeriod, [this] { Step(); }, [this] { return idle_; });

  InstallPsValidators(*stack_);
  InstallListeners();
  // Commands are process data, not parameters: a stored ON would switch the output on at the next
  // power-on before anyone spoke (1010h stores parameters, §2.2.7).
  if (auto* store = stack_->store()) {
    for (std::uint16_t index : {kOutputCommands, kShutdownAck, kReceivedPv})
      store->Exclude(index);
  }
  // §1.2.2: "The controller will wake upon receiving a CAN frame, or when the Remote Enable
  // signal changes state." Awake, it needs no frame its stack does not listen to: its acceptance
  // filter lets every frame through only while it sleeps.
  port_->ObserveFrames([this](const CanFrame&) { sleep_->Wake(); }, [this] { return sleep_->Asleep(); });
  io_subscription_ = io_.Subscribe([this](const IoSignal& signal) {
    if (&signal == signals_.enable) sleep_->Wake();
  });
  // Whatever the loop reads wakes it: inputs, objects, the set of active errors.
  WakeOnChanges(*stack_, io_, [this] { RequestStep(); });
  tick_->Start();
}

void PowerSupply::InstallListeners() {
  auto& od = stack_->od();
  using namespace ps;
  // Network writes that are events, not states (the loop reads the others from the dictionary).
  const auto u8 = [](const canopen::SubObject& sub) {
    return static_cast<std::uint8_t>(canopen::DecodeUnsignedLe(sub.value));
  };
  OdRef(od, kOutputCommands, 2).sub().AddListener([this, u8](canopen::SubObject& sub, Origin origin) {
    if (origin != Origin::kDevice) control_->OnCanCommand(u8(sub));
  });
  for (auto [index, sub_index] :
       {std::pair{kOutputCommands, std::uint8_t{3}}, std::pair{kGeneralCommands, std::uint8_t{2}}}) {
    OdRef(od, index, sub_index).sub().AddListener([this, u8](canopen::SubObject& sub, Origin origin) {
      if (origin != Origin::kDevice && u8(sub) == kQuitFailure) control_->OnQuitFailure();
    });
  }
  OdRef(od, kShutdownAck, 0).sub().AddListener([this, u8](canopen::SubObject& sub, Origin origin) {
    if (origin != Origin::kDevice) control_->OnShutdownAck(u8(sub), scheduler_->Now());
  });
  // A new filter type or constant starts the filter over from its present value.
  for (std::uint16_t index : {kInputFilterType, kInputFilterConstant}) {
    OdRef(od, index, 1).sub().AddListener([this](canopen::SubObject&, Origin) {
      filter_.Reset(filter_.Value());
    });
  }
}

// Power-on and NMT reset node: the stack has restored the parameters and forgotten its errors.
void PowerSupply::OnResetApplication() {
  if (!control_) return;
  const double vin = signals_.vin->Number() / 1000.0;
  control_->Reset(signals_.enable->Is(ps::kLevelHigh));
  input_status_->Reset();
  output_status_->Reset();
  device_status_->Reset();
  input_failure_->Reset();
  output_failure_->Reset();
  protection_.Reset(vin);
  // The filter starts from the first reading (a filter starting at 0 V would report an input
  // failure at every power-on; README.md choice 9).
  filter_.Reset(vin * 1000.0);
  output_on_ = false;
  sleep_->Reset();
  RequestStep();
}

void PowerSupply::OnSleepChange(bool asleep) {
  io_.Publish(*signals_.asleep, asleep);
  if (port_) port_->AcceptanceMayHaveChanged();  // asleep, any frame wakes it
  if (!asleep) RequestStep();
}

void PowerSupply::RequestStep() {
  if (tick_) tick_->Wake();
}

blocks::FilterParams PowerSupply::FilterParams() const {
  blocks::FilterParams p;
  p.type = blocks::DecodeFilterType(static_cast<std::uint8_t>(filter_type_.Get()), false)
               .value_or(blocks::FilterType::kNone);
  p.constant = static_cast<std::uint16_t>(std::max<std::int64_t>(1, filter_constant_.Get()));
  return p;
}

double PowerSupply::CurrentLimit(double vin_filtered_V) const {
  double limit = ps::ManufacturerCurrentLimit(vin_filtered_V);
  // Table 3: 1 = "ds-453 objects", 6205h.8, "does not change in response to any input changes".
  if (limit_control_.Get() == 1)
    limit = static_cast<double>(std::min(set_current_.Get(), max_current_.Get())) / 1000.0;
  return std::clamp(limit, 0.0, static_cast<double>(range_current_.Get()) / 1000.0);
}

double PowerSupply::SetVoltage() const {
  const auto high = std::min(max_voltage_.Get(), range_voltage_.Get());
  const auto low = std::min(min_voltage_.Get(), high);
  return static_cast<double>(std::clamp(set_voltage_.Get(), low, high)) / 1000.0;
}

ps::Load PowerSupply::CurrentLoad() const {
  ps::Load load;
  load.is_resistance = signals_.load_mode->Is(ps::kLoadResistance);
  load.resistance_ohm = signals_.load_resistance->Number();
  load.current_A = signals_.load_current->Number() / 1000.0;
  return load;
}

bool PowerSupply::SleepAllowed() const {
  return sleep_delay_.Get() > 0 && stack_->State() != canopen::NmtState::kOperational &&
         !control_->CommandOn() && !control_->Enabled() && !output_on_;
}

bool PowerSupply::UpdateStatusWords(const ps::OutputPoint& point) {
  using namespace ps;
  // 6201h.1: bits 1-0 output on, 3-2 current limit. 6011h.1: bits 1-0 output on, 3-2 failure
  // active, 5-4 latched (waiting for Quit Failure), 7-6 shutdown countdown, 9-8 hardware input
  // protection, 11-10 current limit. The manual gives no layout (README.md choice 17).
  const std::uint32_t output = Flag(output_on_, 0) | Flag(point.current_limited, 2);
  const std::uint32_t device = Flag(output_on_, 0) | Flag(control_->Failure(), 2) |
                               Flag(control_->Latched(), 4) | Flag(control_->ShuttingDown(), 6) |
                               Flag(!protection_.Ok(), 8) | Flag(point.current_limited, 10);
  bool changed = output_status_word_.Set(output);
  if (device_status_word_.Set(device)) {
    stack_->pdo().NotifyChanged(device_status_word_.sub());
    changed = true;
  }
  return changed;
}

void PowerSupply::Publish(const ps::OutputPoint& point, double limit_A) {
  using namespace ps;
  io_.Publish(*signals_.output_on, output_on_);
  io_.Publish(*signals_.vout, Milli(point.voltage_V));
  io_.Publish(*signals_.iout, Milli(point.current_A));
  io_.Publish(*signals_.iin, Milli(point.input_current_A));
  io_.Publish(*signals_.current_limit, Milli(limit_A));
  io_.Publish(*signals_.current_limited, point.current_limited);
  io_.Publish(*signals_.state, std::string(StateName(control_->State())));
  const char* protection = kProtectionNone;
  if (protection_.state() == InputProtection::State::kUnderVoltage) protection = kProtectionUnder;
  if (protection_.state() == InputProtection::State::kOverVoltage) protection = kProtectionOver;
  io_.Publish(*signals_.protection, std::string(protection));
  io_.Publish(*signals_.commanded_on, control_->CommandOn());
}

void PowerSupply::Step() {
  if (!control_) return;
  // Asleep (§1.2.2) nothing is measured; a frame or the Enable pin wakes the controller.
  if (sleep_->Asleep()) {
    idle_ = true;
    return;
  }
  const TimePoint now = scheduler_->Now();

  // Inputs: one sample per tick. A filter settled on the present input is left alone: another
  // sample would change nothing but the phase of the repeating average's blocks, so a block
  // starts with the first sample after a steady period (README.md choice 9).
  const double vin = signals_.vin->Number() / 1000.0;
  const blocks::FilterParams params = FilterParams();
  if (!filter_.Settled(params, vin * 1000.0)) filter_.Step(params, vin * 1000.0);
  const auto protection_before = protection_.state();
  protection_.Update(vin);
  bool changed = protection_.state() != protection_before;

  // What the output delivers as driven since the last step, measured (§1.2.3: mV, mA; 6020h in
  // 0.1 degC). 6113h is the filtered input: the filter is "added to the input voltage measurement"
  // (§2.4.1), and the current limit follows "the measured input voltage" (Table 3).
  const double limit_A = CurrentLimit(filter_.Value() / 1000.0);
  const ps::Load load = CurrentLoad();
  ps::OutputPoint point = ps::Operate(output_on_, SetVoltage(), vin, limit_A, load);
  changed = input_actual_.Set(Round(filter_.Value())) || changed;
  changed = temperature_.Set(Round(signals_.temperature->Number() * 10.0)) || changed;
  changed = output_voltage_.Set(Round(point.voltage_V * 1000.0)) || changed;
  changed = output_current_.Set(Round(point.current_A * 1000.0)) || changed;

  // CiA 453 fault detection (§1.2.3, §2.3.2, §2.3.9, §2.3.17).
  const std::int64_t vin_mV = input_actual_.Get();
  const std::int64_t temperature = temperature_.Get();
  const std::int64_t vout_mV = output_voltage_.Get();
  const std::int64_t iout_mA = output_current_.Get();
  changed = input_status_->Update(std::array{vin_mV, vin_mV, temperature, temperature}, now) || changed;
  changed = output_status_->Update(std::array{vout_mV, vout_mV, iout_mA, iout_mA}, now) || changed;
  const bool input_failed = input_status_->AnyIndication();
  const bool output_failed = output_status_->AnyIndication();
  const auto device_condition = device_status_->condition().Get();
  changed = device_status_->Update(std::array<std::int64_t, 2>{input_failed, output_failed}, now) || changed;
  if (device_status_->condition().Get() != device_condition)
    stack_->pdo().NotifyChanged(device_status_->condition().sub());
  // Table 9: one FF04h / FF06h entry each, after the 6013h delay (§2.3.3 "the delay before a fault
  // is detected and an EMCY message is sent").
  input_failure_->Update(input_failed, milliseconds(input_delay_.Get()));
  output_failure_->Update(output_failed, milliseconds(output_delay_.Get()));
  const bool failure = input_failure_->Active() || output_failure_->Active();

  // The output state machine, then the power stage.
  changed =
      control_->Update({signals_.enable->Is(ps::kLevelHigh), failure, protection_.Ok()}, now) || changed;
  const bool on = control_->Enabled() && protection_.Ok();
  if (on != output_on_) {
    output_on_ = on;
    changed = true;
    point = ps::Operate(output_on_, SetVoltage(), vin, limit_A, load);
  }
  Publish(point, limit_A);
  changed = UpdateStatusWords(point) || changed;

  sleep_->Update(SleepAllowed(), milliseconds(sleep_delay_.Get()));
  const bool pending = control_->Pending() || input_status_->Pending() || output_status_->Pending() ||
                       device_status_->Pending() ||
                       input_failure_->state() == DelayedFault::State::kPending ||
                       output_failure_->state() == DelayedFault::State::kPending;
  idle_ = !changed && !pending && filter_.Settled(params, vin * 1000.0);
}

ps::OutputState PowerSupply::State() const {
  return control_ ? control_->State() : ps::OutputState::kOff;
}

bool PowerSupply::Asleep() const {
  return sleep_ && sleep_->Asleep();
}

bool PowerSupply::LoopRunning() const {
  return tick_ && tick_->Running() && !tick_->Asleep();
}

}  // namespace canfleet::devices
