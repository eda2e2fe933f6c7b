#include "node/devices/simulated_io.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <stdexcept>

namespace canfleet::devices {

namespace {

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

IoStatus SimulatedIo::Set(std::string_view name, const IoValue& value) {
  auto it = by_name_.find(name);
  if (it == by_name_.end()) return {"unknown signal \"" + std::string(name) + "\""};
  IoSignal& signal = *it->second;
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
  return {};
}

IoStatus SimulatedIo::SetText(std::string_view name, std::string_view text) {
  const IoSignal* signal = Find(name);
  if (!signal) return {"unknown signal \"" + std::string(name) + "\""};
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
  if (!signal) throw std::out_of_range("unknown signal \"" + std::string(name) + "\"");
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
