#include "node/devices/simulated_io.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <stdexcept>

#include "vocabulary/nearest_names.hpp"

namespace canfleet::devices {

namespace {

// The unit rule (node/devices/README.md "Signals"): one unit per quantity, the one the family's
// objects count in, so that an object read by SDO and its signal agree.
constexpr SignalUnit kSignalUnits[] = {
    {"mV", "mV"},
    {"mA", "mA"},
    {"ohm", "ohm"},
    {"Hz", "Hz"},
    {"pct", "pct"},
    {"C", "C"},
    {"rpm", "rpm"},
    {"counts", "counts"},
    {"counts/s", "counts_s"},
    {"pulses/rev", "pulses_per_rev"},
};

bool EndsWithUnit(std::string_view name, std::string_view suffix) {
  if (name.size() <= suffix.size() || !name.ends_with(suffix)) return false;
  const char before = name[name.size() - suffix.size() - 1];
  return before == '_' || before == '.';
}

std::string FormatNumber(double value) {
  // Whole numbers print without a fraction ("2500"), others with up to 6 significant digits.
  char buf[32];
  if (std::nearbyint(value) == value && std::fabs(value) < 1e15) {
    auto r = std::to_chars(buf, buf + sizeof buf, static_cast<long long>(value));
    return std::string(buf, r.ptr);
  }
  auto r = std::to_chars(buf, buf + sizeof buf, value, std::chars_format::general, 6);
  return std::string(buf, r.ptr);
}

std::string JoinChoices(const std::vector<std::string>& choices) {
  std::string out;
  for (const auto& c : choices) {
    if (!out.empty()) out += '|';
    out += c;
  }
  return out;
}

std::string Lower(std::string_view text) {
  std::string out(text);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

const char* KindName(IoKind kind) {
  switch (kind) {
    case IoKind::kNumber:
      return "a number";
    case IoKind::kBool:
      return "a bool";
    case IoKind::kEnum:
      return "one of its choices";
  }
  return "?";
}

bool Matches(IoKind kind, const IoValue& value) {
  switch (kind) {
    case IoKind::kNumber:
      return std::holds_alternative<double>(value);
    case IoKind::kBool:
      return std::holds_alternative<bool>(value);
    case IoKind::kEnum:
      return std::holds_alternative<std::string>(value);
  }
  return false;
}

}  // namespace

std::span<const SignalUnit> SignalUnits() {
  return kSignalUnits;
}

IoSpec NumberSpec(std::string name, std::string unit, double min, double max, double initial,
                  std::string description) {
  IoSpec s;
  s.name = std::move(name);
  s.kind = IoKind::kNumber;
  s.unit = std::move(unit);
  s.min = min;
  s.max = max;
  s.initial = initial;
  s.description = std::move(description);
  return s;
}

IoSpec BoolSpec(std::string name, bool initial, std::string description) {
  IoSpec s;
  s.name = std::move(name);
  s.kind = IoKind::kBool;
  s.initial = initial;
  s.description = std::move(description);
  return s;
}

IoSpec EnumSpec(std::string name, std::vector<std::string> choices, std::string initial,
                std::string description) {
  IoSpec s;
  s.name = std::move(name);
  s.kind = IoKind::kEnum;
  s.choices = std::move(choices);
  s.initial = std::move(initial);
  s.description = std::move(description);
  return s;
}

IoSignal::IoSignal(IoSpec spec, IoDirection direction)
    : spec_(std::move(spec)), direction_(direction), value_(spec_.initial) {}

double IoSignal::Number() const {
  if (const auto* d = std::get_if<double>(&value_)) return *d;
  if (const auto* b = std::get_if<bool>(&value_)) return *b ? 1.0 : 0.0;
  const auto& choice = std::get<std::string>(value_);
  auto it = std::find(spec_.choices.begin(), spec_.choices.end(), choice);
  return static_cast<double>(it - spec_.choices.begin());
}

bool IoSignal::Bool() const {
  if (const auto* b = std::get_if<bool>(&value_)) return *b;
  return Number() != 0.0;
}

std::string_view IoSignal::Enum() const {
  if (const auto* s = std::get_if<std::string>(&value_)) return *s;
  return {};
}

std::string IoSignal::ToString() const {
  switch (spec_.kind) {
    case IoKind::kNumber: {
      std::string text = FormatNumber(Number());
      if (!spec_.unit.empty()) text += " " + spec_.unit;
      return text;
    }
    case IoKind::kBool:
      return Bool() ? "true" : "false";
    case IoKind::kEnum:
      return std::string(Enum());
  }
  return {};
}

IoSignal& SimulatedIo::AddInput(IoSpec spec) {
  return Add(std::move(spec), IoDirection::kInput);
}

IoSignal& SimulatedIo::AddOutput(IoSpec spec) {
  return Add(std::move(spec), IoDirection::kOutput);
}

IoSignal& SimulatedIo::Add(IoSpec spec, IoDirection direction) {
  if (spec.name.empty() || spec.name.find('.') == std::string::npos)
    throw std::logic_error("simulated I/O: signal name \"" + spec.name + "\" is not <channel>.<quantity>");
  if (by_name_.contains(spec.name)) throw std::logic_error("simulated I/O: duplicate signal " + spec.name);
  if (spec.name.size() > kMaxSignalNameLength)
    throw std::logic_error("simulated I/O: " + spec.name + " is longer than telemetry's " +
                           std::to_string(kMaxSignalNameLength) + " characters");
  if (spec.kind == IoKind::kNumber) {
    const auto* unit = std::find_if(std::begin(kSignalUnits), std::end(kSignalUnits),
                                    [&](const SignalUnit& u) { return u.unit == spec.unit; });
    if (unit == std::end(kSignalUnits) || !EndsWithUnit(spec.name, unit->suffix))
      throw std::logic_error("simulated I/O: " + spec.name + " [" + spec.unit +
                             "]: a number's unit is one of the unit rule's and ends its name");
  }
  if (!Matches(spec.kind, spec.initial))
    throw std::logic_error("simulated I/O: initial value of " + spec.name);
  if (spec.kind == IoKind::kEnum && std::find(spec.choices.begin(), spec.choices.end(),
                                              std::get<std::string>(spec.initial)) == spec.choices.end())
    throw std::logic_error("simulated I/O: initial choice of " + spec.name);
  if (spec.kind == IoKind::kNumber && direction == IoDirection::kInput) {
    double v = std::get<double>(spec.initial);
    if (spec.min > spec.max || v < spec.min || v > spec.max)
      throw std::logic_error("simulated I/O: initial value of " + spec.name + " outside its range");
  }
  auto signal = std::unique_ptr<IoSignal>(new IoSignal(std::move(spec), direction));
  IoSignal& ref = *signal;
  by_name_.emplace(ref.name(), &ref);
  signals_.push_back(std::move(signal));
  return ref;
}

void SimulatedIo::Publish(IoSignal& output, IoValue value) {
  Store(output, std::move(value));
}

void SimulatedIo::ResetInputs() {
  for (auto& signal : signals_) {
    if (signal->direction() == IoDirection::kInput) Store(*signal, signal->spec().initial);
  }
}

void SimulatedIo::Store(IoSignal& signal, IoValue value) {
  if (signal.value_ == value) return;
  signal.value_ = std::move(value);
  // Copy the handles first: a listener may unsubscribe itself.
  std::vector<std::size_t> handles;
  handles.reserve(listeners_.size());
  for (const auto& [handle, listener] : listeners_)
    handles.push_back(handle);
  for (std::size_t handle : handles) {
    if (auto it = listeners_.find(handle); it != listeners_.end()) it->second(signal);
  }
}

void SimulatedIo::LoadAliases() const {
  if (alias_table_ == nullptr) return;
  auto* table = alias_table_;
  alias_table_ = nullptr;
  for (IoAlias& alias : table())
    const_cast<SimulatedIo*>(this)->AddAlias(std::move(alias));
}

const std::vector<std::unique_ptr<IoAlias>>& SimulatedIo::Aliases() const {
  LoadAliases();
  return aliases_;
}

void SimulatedIo::AddAlias(IoAlias alias) {
  LoadAliases();
  const IoSignal* target = Find(alias.new_name);
  if (target == nullptr)
    throw std::logic_error("simulated I/O: alias of an unknown signal " + alias.new_name);
  if (by_name_.contains(alias.old_name) || alias_by_name_.contains(alias.old_name))
    throw std::logic_error("simulated I/O: alias " + alias.old_name + " is already a name");
  if (alias.factor != 1.0 && (target->kind() != IoKind::kNumber || !(alias.factor > 0)))
    throw std::logic_error("simulated I/O: alias " + alias.old_name + " converts a number only");
  aliases_.push_back(std::make_unique<IoAlias>(std::move(alias)));
  alias_by_name_.emplace(aliases_.back()->old_name, aliases_.back().get());
}

IoStatus SimulatedIo::Unknown(std::string_view name) const {
  IoStatus status;
  std::vector<std::string> names;
  names.reserve(signals_.size());
  for (const auto& s : signals_)
    names.push_back(s->name());
  status.nearest = NearestNames(name, names);
  status.unknown = true;
  status.error = "no signal " + std::string(name);
  if (!status.nearest.empty()) status.error += "; nearest: " + JoinNames(status.nearest);
  return status;
}

IoName SimulatedIo::Resolve(std::string_view name) const {
  IoName out;
  if (const IoSignal* signal = Find(name)) {
    out.signal = signal;
    return out;
  }
  LoadAliases();
  if (auto it = alias_by_name_.find(name); it != alias_by_name_.end()) {
    out.alias = it->second;
    out.signal = Find(out.alias->new_name);
    out.notice = std::string(name) + " is deprecated: use " + out.alias->new_name;
    if (out.alias->factor != 1.0) {
      // "(1 V = 1000 mV)", "(1000 uA = 1 mA)"
      const double f = out.alias->factor;
      out.notice += " (" +
                    (f < 1 ? "1 " + out.Unit() + " = " + FormatNumber(1 / f)
                           : FormatNumber(f) + " " + out.Unit() + " = 1") +
                    " " + out.signal->spec().unit + ")";
    }
    return out;
  }
  out.error = Unknown(name);
  return out;
}

std::string IoName::Unit() const {
  if (signal == nullptr) return {};
  if (alias == nullptr || alias->factor == 1.0) return signal->spec().unit;
  return alias->old_name.substr(alias->old_name.rfind('_') + 1);  // "current_uA" -> "uA"
}

std::string IoName::ValueText() const {
  if (signal == nullptr) return {};
  if (signal->kind() != IoKind::kNumber) return signal->ToString();
  const double factor = alias == nullptr ? 1.0 : alias->factor;
  return FormatNumber(signal->Number() * factor);
}

std::string IgnoredNotice(const IoSignal& set, std::string_view configuration, std::string_view hint) {
  std::string out = set.name() + " is set, but " + std::string(configuration) + " does not read it";
  if (!hint.empty()) out += " (" + std::string(hint) + ")";
  return out;
}

void SimulatedIo::NoticeIgnored(const IoSignal& signal, IoStatus& status) const {
  if (!ignored_hook_) return;
  const std::string why = ignored_hook_(signal);
  if (why.empty()) return;
  if (!status.notice.empty()) status.notice += "; ";
  status.notice += why;
}

IoStatus SimulatedIo::Set(std::string_view name, const IoValue& value) {
  if (by_name_.find(name) == by_name_.end()) {
    IoName resolved = Resolve(name);
    if (resolved.signal == nullptr) return resolved.error;
    IoValue converted = value;
    if (auto* number = std::get_if<double>(&converted)) *number /= resolved.alias->factor;
    IoStatus status = Set(resolved.signal->name(), converted);
    if (!status.ok()) {
      status.error = std::string(name) + " (now " + resolved.signal->name() + "): " + status.error;
      return status;
    }
    status.notice = resolved.notice + (status.notice.empty() ? "" : "; " + status.notice);
    return status;
  }
  IoSignal& signal = *by_name_.find(name)->second;
  const IoSpec& spec = signal.spec();
  if (signal.direction() != IoDirection::kInput)
    return {spec.name + " is an output: the device sets it, a test only reads it"};
  if (!Matches(spec.kind, value)) {
    std::string expected = KindName(spec.kind);
    if (spec.kind == IoKind::kEnum) expected = JoinChoices(spec.choices);
    return {spec.name + ": expected " + expected};
  }
  if (spec.kind == IoKind::kNumber) {
    double v = std::get<double>(value);
    if (!std::isfinite(v) || v < spec.min || v > spec.max) {
      return {spec.name + ": " + FormatNumber(v) + " is out of range " + FormatNumber(spec.min) + ".." +
              FormatNumber(spec.max) + (spec.unit.empty() ? "" : " " + spec.unit)};
    }
  }
  if (spec.kind == IoKind::kEnum) {
    const auto& choice = std::get<std::string>(value);
    if (std::find(spec.choices.begin(), spec.choices.end(), choice) == spec.choices.end())
      return {spec.name + ": \"" + choice + "\" is not one of " + JoinChoices(spec.choices)};
  }
  Store(signal, value);
  IoStatus status;
  NoticeIgnored(signal, status);
  return status;
}

IoStatus SimulatedIo::SetText(std::string_view name, std::string_view text) {
  const IoName resolved = Resolve(name);
  const IoSignal* signal = resolved.signal;
  if (!signal) return resolved.error;
  switch (signal->kind()) {
    case IoKind::kNumber: {
      double v = 0;
      auto r = std::from_chars(text.data(), text.data() + text.size(), v);
      if (r.ec != std::errc() || r.ptr != text.data() + text.size())
        return {signal->name() + ": \"" + std::string(text) + "\" is not a number"};
      return SetNumber(name, v);
    }
    case IoKind::kBool: {
      std::string t = Lower(text);
      if (t == "true" || t == "on" || t == "1") return SetBool(name, true);
      if (t == "false" || t == "off" || t == "0") return SetBool(name, false);
      return {signal->name() + ": \"" + std::string(text) + "\" is not true/false/on/off/1/0"};
    }
    case IoKind::kEnum:
      return SetEnum(name, text);
  }
  return {"?"};
}

const IoSignal* SimulatedIo::Find(std::string_view name) const {
  auto it = by_name_.find(name);
  return it == by_name_.end() ? nullptr : it->second;
}

const IoSignal& SimulatedIo::Get(std::string_view name) const {
  const IoSignal* signal = Find(name);
  if (!signal) throw std::out_of_range(Unknown(name).error);
  return *signal;
}

double SimulatedIo::Number(std::string_view name) const {
  return Get(name).Number();
}

bool SimulatedIo::Bool(std::string_view name) const {
  return Get(name).Bool();
}

std::string SimulatedIo::Enum(std::string_view name) const {
  return std::string(Get(name).Enum());
}

std::size_t SimulatedIo::Subscribe(Listener listener) {
  std::size_t handle = next_handle_++;
  listeners_.emplace(handle, std::move(listener));
  return handle;
}

void SimulatedIo::Unsubscribe(std::size_t handle) {
  listeners_.erase(handle);
}

}  // namespace canfleet::devices
