#include "node/devices/datalogger_tc_analog/datalogger.hpp"

#include <algorithm>

#include "node/canopen/storage/parameter_store.hpp"
#include "node/devices/datalogger_tc_analog/analog_config.hpp"
#include "node/devices/eds_dictionary.hpp"
#include "node/devices/family/family_error_policy.hpp"

namespace canfleet::devices {

using namespace datalogger;
using canopen::Origin;
using canopen::SdoAbort;
using canopen::SubObject;

namespace {

constexpr std::chrono::milliseconds kOneMs{1};

std::int64_t Decode(const SubObject& sub, std::span<const std::uint8_t> data) {
  if (canopen::IsSigned(sub.type)) return canopen::DecodeSignedLe(data);
  return static_cast<std::int64_t>(canopen::DecodeUnsignedLe(data));
}

// Whole milliseconds of `total`; the rest stays in `carry`.
std::chrono::milliseconds TakeMilliseconds(Duration elapsed, Duration& carry) {
  const Duration total = elapsed + carry;
  const auto ms = std::chrono::floor<std::chrono::milliseconds>(total);
  carry = total - ms;
  return ms;
}

}  // namespace

DataLogger::DataLogger(DeviceOptions options)
    : Device(options.ports), options_(std::move(options)), signals_(io_) {}

DataLogger::~DataLogger() = default;

void DataLogger::Build(std::size_t port, canopen::ObjectDictionary& od) {
  if (port == 0 || shared_od_ == nullptr) {
    od = LoadVariantDictionary(DataLoggerEds(), "datalogger-tc-analog.eds", options_.eds);
    if (port == 0) shared_od_ = &od;
    return;
  }
  // §3: port 2 has communication objects of its own, with the same defaults, and borrows the
  // application objects from port 1 (SharedObjects, DeviceNode::ShareObjects). So it copies only
  // port 1's freshly built 1000h-1FFFh: parsing the EDS again would also make the parse cache
  // keep a third dictionary for the life of the process (about 1 MB of the node's RSS).
  for (const auto& [index, object] : shared_od_->objects())
    if (index < SharedObjects()->first) od.Add(object);
}

void DataLogger::ConfigureStack(std::size_t port, StackSetup& setup) {
  // §3.2.4 Table 26 and §3.2.13: the family's codes (80nn8130h heartbeat, 10008130h life guard,
  // 00008100h RPDO timeout, 00008140h bus-off), 1001h bit 0 only, communication errors react by
  // 1029h sub 1 (README C21), "a maximum of 4 errors in the list" (README C8).
  family::ErrorConventions conventions;
  conventions.history_depth = 4;
  conventions.communication_behaviour_sub = 1;
  setup.policy = std::make_shared<family::FamilyErrorPolicy>(conventions);
  family::ApplyConventions(conventions, setup.options);
  // §3.4.78: 5555h sub 1 is CAN1's "Start in Operational", sub 2 CAN2's (shared object, read
  // after the stored parameters were applied).
  const auto sub = static_cast<std::uint8_t>(port + 1);
  setup.options.start_operational = [this, sub] {
    return shared_od_ != nullptr && shared_od_->GetUnsigned(kStartOperational, sub) != 0;
  };
  setup.hooks.on_reset_application = [this, port] { OnResetApplication(port); };
  // §3.4.79: 5B50h sub 1 is CAN1's bit rate, sub 2 CAN2's (Table 25 indexes), either written from
  // either port; each port runs at its sub's stored value from its next reset (README).
  setup.options.bit_rate_object = canopen::BitRateObject{kChangeBaudRate, sub};
}

void DataLogger::Attach(DeviceContext& context) {
  scheduler_ = &context.scheduler;
  stacks_ = context.stacks;
  powered_.assign(stacks_.size(), false);
  canopen::ObjectDictionary& od = stacks_.at(0)->od();
  shared_od_ = &od;
  const std::span<canopen::CanopenStack* const> stacks(stacks_);

  analog_ = std::make_unique<AnalogInputBlock>(od, signals_, *scheduler_, stacks);
  thermocouples_ = std::make_unique<ThermocoupleBlock>(od, signals_, *scheduler_, stacks);
  diagnostics_ = std::make_unique<DiagnosticsBlock>(od, signals_, *scheduler_, stacks);
  program_ = std::make_unique<ProgramBlocks>(
      od, [this](blocks::SourceKind kind, std::uint8_t number) { return ResolveInput(kind, number); });
  for (int n = 0; n < kReceivedValues; ++n) {
    const std::uint8_t sub = SubOf(n);
    received_[static_cast<std::size_t>(n)] = OdRef(od, kReceivedPv, sub);
    received_digits_[static_cast<std::size_t>(n)] = OdRef(od, kReceivedDigits, sub);
    received_low_[static_cast<std::size_t>(n)] = OdRef(od, kReceivedScaling1, sub);
    received_high_[static_cast<std::size_t>(n)] = OdRef(od, kReceivedScaling2, sub);
  }
  for (int n = 0; n < kConstants; ++n)
    constants_[static_cast<std::size_t>(n)] = OdRef(od, kConstantValue, SubOf(n));

  InstallAnalogValidators(od);
  program_->InstallHooks(od);
  InstallSupplyValidators();
  InstallParameterListeners();
  InstallStorageOnBothPorts();
  // Received values are process data, not parameters: a stored 2500h would feed the blocks at the
  // next power-on before any RPDO arrived (1010h stores parameters, §3.2.7).
  if (auto* store = stacks_[0]->store()) store->Exclude(kReceivedPv);

  cycle_timer_ = std::make_unique<Timer>(*scheduler_, [this] { OnCycle(); });
  conversion_timer_ = std::make_unique<Timer>(*scheduler_, [this] { OnConversion(); });
  io_.Subscribe([this](const IoSignal& signal) { OnPinChanged(signal); });
  io_.SetIgnoredHook([this](const IoSignal& input) { return analog_->IgnoredInput(input); });
}

// ---- Reset -------------------------------------------------------------------------------------

// README "Reset node": the manual describes no NMT reset and calls the unit one "module" (§3.1.1).
// A reset node on either port is a reset of the device's application: the shared objects go back
// to their power-on values (defaults, then stored values) and the blocks start over; the other
// port's NMT state and communication objects are untouched and it sends no boot-up. Port 1's
// stack restores the shared objects itself (they are its own); port 2's reset does it here.
void DataLogger::OnResetApplication(std::size_t port) {
  if (!analog_) return;  // not attached yet
  const bool power_on = !powered_.at(port);
  powered_[port] = true;
  if (port != 0 && !power_on) {
    canopen::CanopenStack& primary = *stacks_[0];
    shared_od_->RestoreDefaults(0x2000, 0xFFFF, primary.NodeId());
    if (auto* store = primary.store()) store->ApplyStored(0x2000, 0xFFFF, primary.NodeId());
  }
  // The resetting port's stack forgot its errors (EMCY ClearAll): its records start inactive.
  analog_->ResetPort(port);
  thermocouples_->ResetPort(port);
  diagnostics_->ResetPort(port);
  // At power-on port 1's reset starts the application; port 2's power-on joins it.
  if (port == 0 || !power_on) RestartApplication();
}

void DataLogger::RestartApplication() {
  const TimePoint now = scheduler_->Now();
  power_on_ = now;
  last_inputs_ = now;
  last_program_ = now;
  inputs_carry_ = Duration::zero();
  program_carry_ = Duration::zero();
  analog_->Reset();
  thermocouples_->Reset();
  diagnostics_->Reset();
  program_->Reset();
  conversion_timer_->Cancel();
  // The reset put the measured objects back to their defaults; the converter has its values.
  thermocouples_->Convert();
  ++conversions_;
  idle_ = false;
  cycle_timer_->StartAt(power_on_ + kScanPeriod);
}

// ---- Events ------------------------------------------------------------------------------------

void DataLogger::OnPinChanged(const IoSignal& signal) {
  if (!analog_) return;
  const bool thermocouple =
      &signal == signals_.cold_junction ||
      std::find(signals_.tc_temperature.begin(), signals_.tc_temperature.end(), &signal) !=
          signals_.tc_temperature.end() ||
      std::find(signals_.tc_open.begin(), signals_.tc_open.end(), &signal) != signals_.tc_open.end();
  if (thermocouple) {
    RequestConversion();
    return;
  }
  // The filters ran with the old value up to now; from now on they see the new one.
  AdvanceInputs();
  analog_->Latch();
  RequestCycle();
}

void DataLogger::OnParameterWritten(const SubObject& sub, Origin origin) {
  // The device's own writes (outputs, Table 11 updates, restores) are followed by a cycle anyway.
  if (origin == Origin::kDevice) return;
  const std::uint16_t index = sub.index;
  if ((index == kSensorType && sub.sub_index > kTcTypeSubOffset) || index == kTcColdJunctionEnabled) {
    RequestConversion();
    return;
  }
  if (sub.sub_index >= 1 && sub.sub_index <= kAnalogInputs &&
      (index == kSensorType || index == kAiRange || index == kAiPulsesPerRev || index == kAiOperatingMode))
    analog_->OnConfigWritten(sub.sub_index - 1, index == kSensorType);
  if (index == kDiPullup || index == kDiPolarity || index == kAiOperatingMode) {
    AdvanceInputs();
    analog_->Latch();  // an open pin's level follows the pull-up
  }
  RequestCycle();
}

TimePoint DataLogger::BoundaryAtOrAfter(TimePoint t, Duration period) const {
  if (t <= power_on_) return power_on_;
  const auto periods = (t - power_on_ + period - Duration{1}) / period;
  return power_on_ + periods * period;
}

void DataLogger::RequestCycle() {
  if (idle_) {
    // Nothing was counting since the last cycle; the filters start from now.
    AdvanceInputs();
    last_program_ = scheduler_->Now();
    program_carry_ = Duration::zero();
    idle_ = false;
  }
  // At least one filter call (1 ms) before the values are published.
  const TimePoint due = BoundaryAtOrAfter(scheduler_->Now() + kOneMs, kScanPeriod);
  if (!cycle_timer_->Armed() || cycle_timer_->Deadline() > due) cycle_timer_->StartAt(due);
}

void DataLogger::RequestConversion() {
  if (conversion_timer_->Armed()) return;
  conversion_timer_->StartAt(BoundaryAtOrAfter(scheduler_->Now() + Duration{1}, kConversionPeriod));
}

void DataLogger::OnConversion() {
  ++conversions_;
  thermocouples_->Convert();
  cycle_timer_->Cancel();
  OnCycle();  // the limits are checked on the new values at once
}

void DataLogger::AdvanceInputs() {
  const TimePoint now = scheduler_->Now();
  auto elapsed = TakeMilliseconds(now - last_inputs_, inputs_carry_);
  last_inputs_ = now;
  // After an idle stretch the filters had settled and no delay was counting: that time changed
  // nothing, and one scan is enough to take a parameter change into account.
  if (idle_) elapsed = std::min(elapsed, std::chrono::duration_cast<std::chrono::milliseconds>(kScanPeriod));
  analog_->Advance(elapsed);
}

void DataLogger::OnCycle() {
  ++cycles_;
  const TimePoint now = scheduler_->Now();
  AdvanceInputs();
  analog_->Publish();
  thermocouples_->EvaluateFaults();
  diagnostics_->Update();
  const auto elapsed = TakeMilliseconds(now - last_program_, program_carry_);
  last_program_ = now;
  const bool moved = program_->Update(elapsed);

  // What wakes the next cycle: a filter settling, a table ramping or outputs still moving (every
  // scan); a span delay or a held time response (once, at its end); nothing (idle).
  std::optional<Duration> next;
  const auto ramp = program_->NextChange();
  if (analog_->Settling() || moved || (ramp && ramp->count() == 0)) {
    next = kScanPeriod;
  } else {
    for (const auto& wait : {analog_->NextDelayEnd(), ramp}) {
      if (wait && (!next || *wait < *next)) next = std::max<Duration>(*wait, kScanPeriod);
    }
  }
  idle_ = !next.has_value();
  if (next) cycle_timer_->StartAt(BoundaryAtOrAfter(now + *next, kScanPeriod));
}

// ---- Wiring ------------------------------------------------------------------------------------

blocks::Signal DataLogger::ResolveInput(blocks::SourceKind kind, std::uint8_t number) const {
  using blocks::SourceKind;
  const int i = number - 1;
  switch (kind) {
    case SourceKind::kCanMessage: {
      if (number < 1 || number > kReceivedValues) break;
      const auto n = static_cast<std::size_t>(i);
      blocks::Signal s;
      s.value = static_cast<double>(received_[n].Get());
      s.min = static_cast<double>(received_low_[n].Get());
      s.max = static_cast<double>(received_high_[n].Get());
      s.decimal_digits = static_cast<std::uint8_t>(received_digits_[n].Get());
      return s;
    }
    case SourceKind::kAnalogInput:
      if (number < 1 || number > kAnalogInputs) break;
      return analog_->Source(i);
    case SourceKind::kColdJunction:
      if (number < 1 || number > kThermocouples) break;
      return thermocouples_->ColdJunctionSource(i);
    case SourceKind::kThermocouple:
      if (number < 1 || number > kThermocouples) break;
      return thermocouples_->TemperatureSource(i);
    case SourceKind::kConstant:
      if (number < 1 || number > kConstants) break;
      return blocks::Signal::Constant(constants_[static_cast<std::size_t>(i)].GetNumber());
    case SourceKind::kSupplyVoltage:
      return diagnostics_->SupplySource();
    case SourceKind::kProcessorTemperature:
      return diagnostics_->TemperatureSource();
    default:
      break;
  }
  return blocks::Signal::NotAvailable();
}

void DataLogger::InstallParameterListeners() {
  // Every network-writable application object wakes the application (an RPDO into 2500h too).
  // One listener per port's dictionary (port 2 writes them through its borrowed objects) rather
  // than one per sub-object (1600 of them, ~130 bytes each of idle RSS). They run after the
  // sub-objects' own listeners, as these did, being installed last.
  for (auto* stack : stacks_) {
    stack->od().AddWriteListener([this](SubObject& s, Origin origin) {
      if (s.index >= 0x2000 && s.index <= 0x7FFF && canopen::IsWritable(s.access))
        OnParameterWritten(s, origin);
    });
  }
}

void DataLogger::InstallSupplyValidators() {
  // §3.4.70-71: 5022h "0V ... Object 5023h", 5023h "Object 5022h ... 36V".
  OdRef under(*shared_od_, kUnderVoltage, 0);
  OdRef over(*shared_od_, kOverVoltage, 0);
  under.sub().AddValidator([over](const SubObject& s, std::span<const std::uint8_t> data, Origin) {
    return Decode(s, data) <= over.Get() ? SdoAbort::kNone : SdoAbort::kValueTooHigh;
  });
  over.sub().AddValidator([under](const SubObject& s, std::span<const std::uint8_t> data, Origin) {
    return Decode(s, data) >= under.Get() ? SdoAbort::kNone : SdoAbort::kValueTooLow;
  });
}

// §3.2.7/§3.2.8: "The 'save' [load] action on either CAN buses will apply to the parameters on
// both buses." DeviceNode already sends a port-2 command's shared part (2000h-FFFFh) to port 1's
// store; here the communication part goes to the other port's store as well, so that "save all"
// or "save communication" on either bus also keeps the other bus's 1000h-1FFFh.
void DataLogger::InstallStorageOnBothPorts() {
  for (std::size_t p = 0; p < stacks_.size(); ++p) {
    for (const std::uint16_t index : {std::uint16_t{0x1010}, std::uint16_t{0x1011}}) {
      const bool store = index == 0x1010;
      const std::uint32_t signature = store ? canopen::kSaveSignature : canopen::kLoadSignature;
      for (const std::uint8_t sub_index : {std::uint8_t{1}, std::uint8_t{2}}) {
        SubObject* sub = stacks_[p]->od().Find(index, sub_index);
        if (!sub) continue;
        sub->AddValidator(
            [this, p, store, signature](const SubObject&, std::span<const std::uint8_t> data, Origin) {
              if (data.size() != 4 || canopen::DecodeUnsignedLe(data) != signature) return SdoAbort::kNone;
              for (std::size_t q = 0; q < stacks_.size(); ++q) {
                canopen::ParameterStore* other = q == p ? nullptr : stacks_[q]->store();
                if (!other) continue;
                const SdoAbort rc = store ? other->Save(2) : other->MarkRestoreDefaults(2);
                if (rc != SdoAbort::kNone) return rc;
              }
              return SdoAbort::kNone;
            });
      }
    }
  }
}

}  // namespace canfleet::devices
